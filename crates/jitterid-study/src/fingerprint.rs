//! The identity of an experiment by content: a fingerprint of every parsed value, so that the
//! same experiment under two paths is one study and an edited file is another.
//!
//! The fingerprint decides whether shard files may be merged into one study, so it is a
//! cryptographic digest (SHA-256): two different experiments cannot be made to collide, by
//! accident or on purpose, as they could under a 64-bit hash.

use crate::experiment::Experiment;
use sha2::{Digest, Sha256};
use std::fmt::Write as _;

/// The fingerprint of `exp`: the SHA-256 digest (64 hexadecimal digits) of the canonical text
/// of every parsed value (sampling, input, system, jitter, noise, estimate and title). Numbers
/// enter with their shortest round-trip text, so two values give the same fingerprint only if
/// they are equal; the file's name, comments, layout and key order do not enter.
pub fn experiment_fingerprint(exp: &Experiment) -> String {
    let mut h = HashWriter(Sha256::new());
    // Writing into a hasher cannot fail.
    // One input is written as it was before inputs had names and could be several, so that
    // such an experiment keeps its fingerprint (and its studies stay mergeable).
    let _ = write!(h, "title={:?}\ngrid={:?}\ninput=", exp.title, exp.grid);
    match exp.inputs.as_slice() {
        [] => {
            let _ = write!(h, "None");
        }
        [one] => {
            let _ = write!(h, "{:?}", one.spec);
        }
        several => {
            let _ = write!(h, "{several:?}");
        }
    }
    let _ = write!(
        h,
        "\nsystem={:?}\njitter={:?}\nnoise={:?}\nestimate={:?}",
        exp.system, exp.jitter, exp.noise, exp.estimate
    );
    if let [one] = exp.inputs.as_slice() {
        // Entered only when given, so that an experiment without them keeps its fingerprint.
        if one.history != 0.0 {
            let _ = write!(h, "\nhistory={:?}", one.history);
        }
        if one.name != "u" {
            let _ = write!(h, "\ninput_name={:?}", one.name);
        }
    }
    let mut hex = String::with_capacity(64);
    for byte in h.0.finalize() {
        let _ = write!(hex, "{byte:02x}");
    }
    hex
}

/// Feeds formatted text straight into the digest, so that a long measured input is hashed
/// without first being written out as one string.
struct HashWriter(Sha256);

impl std::fmt::Write for HashWriter {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        self.0.update(s.as_bytes());
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::{parse, Purpose};
    use std::path::Path;

    const BASE: &str = r#"[sampling]
interval = 1.0
samples = 64
[input]
kind = "random-binary"
mean_dwell = 8.0
[system]
kind = "zpk"
gain = 1.0
poles = [-0.5]
[jitter]
family = "gaussian"
sigma = 0.1
[noise]
std = 0.01
"#;

    fn fp(text: &str) -> String {
        experiment_fingerprint(&parse("e.toml", text, Path::new("."), Purpose::Simulate).unwrap())
    }

    /// The digest is SHA-256 of the canonical text: checked against an independent
    /// implementation's digest of a known message (FIPS 180-2, appendix B.1).
    #[test]
    fn the_digest_is_sha256() {
        let mut h = HashWriter(Sha256::new());
        // In two writes, as the fingerprint feeds its fields.
        let middle = 'b';
        let _ = write!(h, "a{middle}");
        let _ = write!(h, "c");
        let hex: String = h.0.finalize().iter().map(|b| format!("{b:02x}")).collect();
        assert_eq!(
            hex,
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }

    #[test]
    fn every_value_changes_the_fingerprint() {
        let base = fp(BASE);
        for (from, to) in [
            ("interval = 1.0", "interval = 0.5"),
            ("samples = 64", "samples = 65"),
            ("mean_dwell = 8.0", "mean_dwell = 9.0"),
            ("gain = 1.0", "gain = 2.0"),
            ("poles = [-0.5]", "poles = [-0.25]"),
            ("sigma = 0.1", "sigma = 0.100000001"),
            ("std = 0.01", "std = 0.02"),
            ("mean_dwell = 8.0", "mean_dwell = 8.0\nhistory = 5.0"),
            ("poles = [-0.5]", "poles = [-0.5]\ndelay = 0.5"),
            ("poles = [-0.5]", "poles = [-0.5]\ninitial = \"estimate\""),
            ("[noise]", "[estimate]\nmethod = \"ls\"\n[noise]"),
            ("[sampling]", "title = \"other\"\n[sampling]"),
        ] {
            let edited = BASE.replace(from, to);
            assert_ne!(edited, BASE, "{from}");
            assert_ne!(fp(&edited), base, "{from} → {to} kept the fingerprint");
        }
    }

    #[test]
    fn layout_comments_and_number_spelling_do_not() {
        let base = fp(BASE);
        let same = BASE
            .replace(
                "interval = 1.0",
                "# the sampling interval\ninterval   =   1",
            )
            .replace("gain = 1.0", "gain = 1e0")
            .replace("std = 0.01", "std = 1.0e-2");
        assert_eq!(fp(&same), base);
        let reordered = BASE.replace(
            "interval = 1.0\nsamples = 64",
            "samples = 64\ninterval = 1.0",
        );
        assert_eq!(fp(&reordered), base);
        assert_eq!(base.len(), 64);
        assert!(base.bytes().all(|b| b.is_ascii_hexdigit()));
    }
}
