//! What every reproduction case shares: where its runs start and end under `--shard`, how an
//! optional number prints, and how its JSON and Markdown are written.

use crate::Options;

/// An optional number to four decimals, `–` when absent.
pub(crate) fn fmt_opt(x: Option<f64>) -> String {
    x.map_or("–".into(), |v| format!("{v:.4}"))
}

/// Writes the case's JSON and Markdown under `--out` (with the shard in their names), the JSON
/// also to `--json` when given, and prints the Markdown.
pub(crate) fn write_outputs(
    case: &str,
    o: &Options,
    value: &serde_json::Value,
    md: &str,
) -> Result<(), String> {
    std::fs::create_dir_all(&o.out).map_err(|e| format!("{}: {e}", o.out))?;
    let text = serde_json::to_string_pretty(value).map_err(|e| e.to_string())?;
    let suffix = if o.shard.1 > 1 {
        format!(".shard{}of{}", o.shard.0, o.shard.1)
    } else {
        String::new()
    };
    for (path, body) in [
        (format!("{}/{case}{suffix}.json", o.out), &text),
        (format!("{}/{case}{suffix}.md", o.out), &md.to_string()),
    ] {
        std::fs::write(&path, body).map_err(|e| format!("{path}: {e}"))?;
    }
    if let Some(path) = &o.json {
        std::fs::write(path, text).map_err(|e| format!("{path}: {e}"))?;
    }
    println!("{md}");
    Ok(())
}

/// The runs of this shard of the case's `--runs` (or `default`).
pub(crate) fn runs_range(o: &Options, default: u64) -> std::ops::Range<u64> {
    let total = o.runs.unwrap_or(default);
    let (i, n) = o.shard;
    (total * i / n)..(total * (i + 1) / n)
}
