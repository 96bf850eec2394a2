//! Property tests ("fuzzing") of the readers: the TOML experiment parser and the CSV parser
//! must never panic, and every error must be one line that starts with the file's name.

use jitterid_study::{csvio, experiment};
use proptest::prelude::*;
use std::path::{Path, PathBuf};

/// Cases per property (each property below runs this many inputs); `JITTERID_FUZZ_CASES`
/// overrides it for a longer run, and `JITTERID_FUZZ_SEED` (an integer) draws other inputs.
const CASES: u32 = 300;

fn config() -> ProptestConfig {
    ProptestConfig {
        cases: std::env::var("JITTERID_FUZZ_CASES")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(CASES),
        failure_persistence: None,
        // Fixed by default so that CI runs the same inputs every time; JITTERID_FUZZ_SEED picks
        // other inputs for a long run.
        rng_seed: proptest::test_runner::RngSeed::Fixed(
            std::env::var("JITTERID_FUZZ_SEED")
                .ok()
                .and_then(|s| s.parse().ok())
                .unwrap_or(0x0063_6c69),
        ),
        ..ProptestConfig::default()
    }
}

fn example_texts() -> Vec<String> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/experiments");
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    v.sort();
    v.iter()
        .map(|p| std::fs::read_to_string(p).unwrap())
        .collect()
}

/// An empty directory: `kind = "csv"` inputs resolve against it and find nothing.
fn empty_dir() -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join("jitterid-study-fuzz-empty");
    let _ = std::fs::create_dir_all(&d);
    d
}

fn check_toml(text: &str) {
    if let Err(e) = experiment::parse(
        "fuzz.toml",
        text,
        &empty_dir(),
        experiment::Purpose::Simulate,
    ) {
        let m = e.message();
        assert!(
            !m.contains('\n') && !m.contains('\r'),
            "not one line: {m:?}"
        );
        assert!(m.starts_with("fuzz.toml"), "file not named first: {m:?}");
    }
}

fn check_csv(text: &str) {
    match csvio::parse("fuzz.csv", text) {
        Ok(t) => {
            assert!(t.rows() >= 1);
            assert!(t.values.iter().all(|c| c.len() == t.rows()));
            assert!(t.values.iter().flatten().all(|v| v.is_finite()));
        }
        Err(e) => {
            let m = e.to_string();
            assert!(
                !m.contains('\n') && !m.contains('\r'),
                "not one line: {m:?}"
            );
            assert!(m.starts_with("fuzz.csv"), "file not named first: {m:?}");
        }
    }
}

/// Tokens that TOML and CSV parsers care about.
fn token() -> impl Strategy<Value = String> {
    prop_oneof![
        Just("=".to_string()),
        Just("[".to_string()),
        Just("]".to_string()),
        Just("[[".to_string()),
        Just("{".to_string()),
        Just("}".to_string()),
        Just(",".to_string()),
        Just("\"".to_string()),
        Just("'".to_string()),
        Just("\n".to_string()),
        Just("\r\n".to_string()),
        Just("#".to_string()),
        Just(".".to_string()),
        Just("nan".to_string()),
        Just("inf".to_string()),
        Just("-inf".to_string()),
        Just("1e309".to_string()),
        Just("-0".to_string()),
        Just("0".to_string()),
        Just("1".to_string()),
        Just("-1".to_string()),
        Just("3.5".to_string()),
        Just("1e-300".to_string()),
        Just("9223372036854775807".to_string()),
        Just("true".to_string()),
        Just("\"zpk\"".to_string()),
        Just("\"tf\"".to_string()),
        Just("\"sinusoid\"".to_string()),
        Just("\"csv\"".to_string()),
        Just("\"uniform-sum\"".to_string()),
        Just("\"gaussian\"".to_string()),
        Just("\"two-point\"".to_string()),
        Just("\"none\"".to_string()),
        Just("\"multisine\"".to_string()),
        Just("\"piecewise\"".to_string()),
        Just("\"arma\"".to_string()),
        Just("\"ml\"".to_string()),
        Just("[[-0.1, 0.2]]".to_string()),
        Just("[0.0, 0.0]".to_string()),
        Just("{ min = 0.0, max = 0.1 }".to_string()),
        Just("kind".to_string()),
        Just("family".to_string()),
        Just("samples".to_string()),
        Just("interval".to_string()),
        Just("poles".to_string()),
        Just("y".to_string()),
        Just("k,t,y".to_string()),
        Just("\u{feff}".to_string()),
        Just("é".to_string()),
        "[a-z_]{1,8}",
        "-?[0-9]{1,4}(\\.[0-9]{0,3})?(e-?[0-9]{1,3})?",
    ]
}

/// Applies random edits (insert a token, delete a span, duplicate a line) to `text`.
fn mutate(text: &str, edits: &[(usize, u8, String)]) -> String {
    let mut chars: Vec<char> = text.chars().collect();
    for (pos, op, tok) in edits {
        let n = chars.len();
        let at = if n == 0 { 0 } else { pos % (n + 1) };
        match op % 4 {
            0 => {
                let t: Vec<char> = tok.chars().collect();
                chars.splice(at..at, t);
            }
            1 => {
                let end = (at + 1 + pos % 7).min(n);
                if at < end {
                    chars.drain(at..end);
                }
            }
            2 => {
                // Replace the rest of the line from `at` with the token.
                let end = chars[at..]
                    .iter()
                    .position(|c| *c == '\n')
                    .map_or(n, |p| at + p);
                chars.splice(at..end, tok.chars());
            }
            _ => {
                // Duplicate the line at `at` (repeated keys and sections).
                let start = chars[..at]
                    .iter()
                    .rposition(|c| *c == '\n')
                    .map_or(0, |p| p + 1);
                let end = chars[at..]
                    .iter()
                    .position(|c| *c == '\n')
                    .map_or(n, |p| at + p + 1);
                let line: Vec<char> = chars[start..end].to_vec();
                chars.splice(start..start, line);
            }
        }
    }
    chars.into_iter().collect()
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn toml_reader_survives_mutated_examples(
        which in 0usize..64,
        edits in prop::collection::vec((any::<usize>(), any::<u8>(), token()), 1..6),
    ) {
        let texts = example_texts();
        let text = mutate(&texts[which % texts.len()], &edits);
        check_toml(&text);
    }

    #[test]
    fn toml_reader_survives_token_soup(tokens in prop::collection::vec(token(), 0..40)) {
        check_toml(&tokens.join(" "));
    }

    #[test]
    fn toml_reader_survives_arbitrary_text(text in "\\PC{0,400}") {
        check_toml(&text);
    }

    #[test]
    fn csv_reader_survives_structured_tables(
        header in prop::collection::vec("[a-z]{0,3}|y|t|k|\"y\"|1.5", 0..5),
        rows in prop::collection::vec(prop::collection::vec(token(), 0..6), 0..10),
    ) {
        let mut text = header.join(",");
        text.push('\n');
        for r in rows {
            text.push_str(&r.join(","));
            text.push('\n');
        }
        check_csv(&text);
    }

    #[test]
    fn csv_reader_survives_arbitrary_text(text in "\\PC{0,400}") {
        check_csv(&text);
    }

    #[test]
    fn csv_reader_survives_mutated_data(
        edits in prop::collection::vec((any::<usize>(), any::<u8>(), token()), 1..6),
    ) {
        let mut good = String::from("k,t,y,u\n");
        for k in 0..20 {
            good.push_str(&format!("{k},{k}.0,{},{}\n", (k as f64).sin(), k % 2));
        }
        check_csv(&mutate(&good, &edits));
    }
}
