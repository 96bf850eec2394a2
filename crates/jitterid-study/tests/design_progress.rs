//! The design searches' progress observer ([`Plan::with_observer`]): it sees every design the
//! search evaluates, numbered in order, and every prior draw of a robust design, and the
//! report with an observer is the report without one, to the byte.

mod common;

use common::{plan as read_plan, setup, RANDOM_BINARY};
use jitterid_study::design::{design, jitter_blind, DesignObserver, DesignProgress};
use std::sync::{Arc, Mutex};

/// The Table 2 setup, shortened, with a cheap robust dwell search.
fn table2_robust() -> String {
    setup(
        100,
        RANDOM_BINARY,
        "[design]\nmean_dwell = [2.0, 20.0]\ndraws = 2\ngrid = 3\nprior_spread = 0.05\nprior_draws = 2",
    )
}

/// The events of one run, recorded in order.
fn recorder() -> (DesignObserver, Arc<Mutex<Vec<DesignProgress>>>) {
    let seen = Arc::new(Mutex::new(Vec::new()));
    let into = Arc::clone(&seen);
    let observer = DesignObserver::new(move |p| into.lock().unwrap().push(*p));
    (observer, seen)
}

#[test]
fn the_observer_sees_every_evaluation_and_changes_nothing() {
    let plan = read_plan(&table2_robust()).unwrap();
    let quiet = design(&plan, None).unwrap();
    let quiet_blind = jitter_blind(&plan, &quiet.criterion).unwrap();
    let (observer, seen) = recorder();
    let watched_plan = plan.with_observer(observer);
    let watched = design(&watched_plan, None).unwrap();
    let watched_blind = jitter_blind(&watched_plan, &watched.criterion).unwrap();
    let mut quiet_report = quiet.clone();
    quiet_report.jitter_blind = Some(quiet_blind);
    let mut watched_report = watched.clone();
    watched_report.jitter_blind = Some(watched_blind);
    // The JSON the command prints is the same to the byte.
    assert_eq!(
        serde_json::to_string_pretty(&quiet_report.json()).unwrap(),
        serde_json::to_string_pretty(&watched_report.json()).unwrap()
    );
    let seen = seen.lock().unwrap().clone();
    let evaluated = |blind: bool| -> Vec<(usize, usize)> {
        seen.iter()
            .filter_map(|p| match *p {
                DesignProgress::Evaluated {
                    jitter_blind,
                    evaluations,
                    grid_points,
                } if jitter_blind == blind => Some((evaluations, grid_points)),
                _ => None,
            })
            .collect()
    };
    // One report per evaluated design, numbered 1, 2, …, with the grid's size (3 points).
    let aware = evaluated(false);
    assert_eq!(aware.len(), watched.evaluations);
    for (i, &(n, grid)) in aware.iter().enumerate() {
        assert_eq!((n, grid), (i + 1, 3));
    }
    let blind = evaluated(true);
    assert!(!blind.is_empty());
    for (i, &(n, grid)) in blind.iter().enumerate() {
        assert_eq!((n, grid), (i + 1, 3));
    }
    // Every evaluated design of the jitter-aware search and the baseline average the
    // criterion over both prior draws, each reported as 1/2 then 2/2; so do the blind
    // search's designs and its design under the true prior.
    let draws: Vec<(usize, usize)> = seen
        .iter()
        .filter_map(|p| match *p {
            DesignProgress::PriorDraw { done, total } => Some((done, total)),
            _ => None,
        })
        .collect();
    assert_eq!(draws.len(), 2 * (aware.len() + 1 + blind.len() + 1));
    for pair in draws.chunks(2) {
        assert_eq!(pair, [(1, 2), (2, 2)]);
    }
}

/// A multisine's descent reports each design it evaluates too (without a grid), numbered
/// `1 … evaluations` in some order (its gradient's components run in parallel), and the report
/// with the observer is the report without it. The jitter-blind search that gives the descent
/// its second start reports as the jitter-blind search, numbered `1 …` on its own.
#[test]
fn a_multisine_search_reports_every_evaluation() {
    let text = setup(
        100,
        "kind = \"multisine\"\nfrequencies = [0.03, 0.1, 0.3]\namplitudes = [0.3, 0.3, 0.3]",
        "[design]\nband = [0.01, 0.4]\ntones = 3",
    );
    let plan = read_plan(&text).unwrap();
    let quiet = design(&plan, None).unwrap();
    let (observer, seen) = recorder();
    let watched = design(&plan.with_observer(observer), None).unwrap();
    assert_eq!(
        serde_json::to_string_pretty(&quiet.json()).unwrap(),
        serde_json::to_string_pretty(&watched.json()).unwrap()
    );
    let (mut aware, mut blind) = (Vec::new(), Vec::new());
    for p in seen.lock().unwrap().iter() {
        match *p {
            DesignProgress::Evaluated {
                jitter_blind,
                evaluations,
                grid_points: 0,
            } => {
                if jitter_blind {
                    blind.push(evaluations)
                } else {
                    aware.push(evaluations)
                }
            }
            other => panic!("unexpected {other:?}"),
        }
    }
    aware.sort_unstable();
    assert_eq!(aware, (1..=watched.evaluations).collect::<Vec<_>>());
    blind.sort_unstable();
    assert!(!blind.is_empty());
    assert_eq!(blind, (1..=blind.len()).collect::<Vec<_>>());
}
