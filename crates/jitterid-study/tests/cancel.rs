//! A study stops when its front end asks: the realisations not yet started are not run, and the
//! study ends with an error instead of a partial result.

use jitterid_study::experiment::{self, Purpose};
use jitterid_study::montecarlo::{run_study, Keep};
use jitterid_study::{RunsDone, Watch};
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;

const EXPERIMENT: &str = r#"
[sampling]
interval = 1.0
samples = 200

[input]
kind = "random-binary"
mean_dwell = 8.0

[system]
kind = "zpk"
gain = 1.0
poles = [-2.0]
estimate = true

[jitter]
family = "uniform-sum"
n = 0
a = 0.5

[noise]
std = 0.01

[estimate]
method = "bcls"
perturb = 0.2
"#;

#[test]
fn a_cancelled_study_stops_before_its_next_realisation() {
    let exp = experiment::parse(
        "e.toml",
        EXPERIMENT,
        Path::new("."),
        Purpose::Estimate(None),
    )
    .unwrap();
    let cancel = Arc::new(AtomicBool::new(false));
    let seen = Arc::new(AtomicU64::new(0));
    let (flag, count) = (Arc::clone(&cancel), Arc::clone(&seen));
    let watch = Watch {
        // The front end's Ctrl-C, arriving as the third realisation finishes.
        runs: Some(Arc::new(move |p: RunsDone| {
            count.store(p.done, Ordering::Relaxed);
            if p.done >= 3 {
                flag.store(true, Ordering::Relaxed);
            }
        })),
        cancel: Some(Arc::clone(&cancel)),
        ..Watch::none()
    };
    let err = run_study(&exp, 10_000, 1, None, Some(1), Keep::default(), &watch).unwrap_err();
    assert_eq!(
        err.to_string(),
        "interrupted: the study was stopped after 3 of 10000 realisations"
    );
    assert_eq!(seen.load(Ordering::Relaxed), 3);

    // Not asked to stop, the same watcher lets a study finish.
    cancel.store(false, Ordering::Relaxed);
    let quiet = Watch {
        cancel: Some(Arc::new(AtomicBool::new(false))),
        ..Watch::none()
    };
    let done = run_study(&exp, 4, 1, None, Some(1), Keep::default(), &quiet).unwrap();
    assert_eq!(done.json.runs, 4);
}
