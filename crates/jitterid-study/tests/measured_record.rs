//! Measured records: CSV round trips, malformed files named by line and column, and a model
//! evaluated on another record's input.

use jitterid::estimate::{InputLayout, MeasuredRecord, Record};
use jitterid::signal::registry::SignalRegistry;
use jitterid::signal::{Input, PiecewiseConstant, SampleGrid, Signal};
use jitterid_study::csvio::{
    input_to_csv, load_record, parse, record_from_table, record_to_csv, save_record, CsvError,
};
use proptest::prelude::*;

fn scratch(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("jitterid-measured-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

proptest! {
    #[test]
    fn a_record_and_its_input_read_back(
        t0 in -100.0..100.0f64,
        interval in 1e-3..10.0f64,
        y in prop::collection::vec(-1e6..1e6f64, 2..60),
        steps in prop::collection::vec((1e-3..5.0f64, -3.0..3.0f64), 1..12),
    ) {
        let n = y.len();
        let grid = SampleGrid::new(t0, interval, n).unwrap();
        let mut edges = vec![t0];
        let mut levels = Vec::new();
        for (dt, level) in &steps {
            edges.push(edges[edges.len() - 1] + dt);
            levels.push(*level);
        }
        let input = PiecewiseConstant::new(edges, levels).unwrap();
        let rec = MeasuredRecord::new("r", Record::new(grid, y.clone()).unwrap())
            .with_input(Input::Piecewise(input.clone()));
        // The data file alone: samples exact, the grid to rounding, the input held.
        let table = parse("r.csv", &record_to_csv(&rec)).unwrap();
        let back = record_from_table(&table, None).unwrap();
        prop_assert_eq!(back.y(), &y[..]);
        prop_assert!((back.grid().start() - t0).abs() <= 1e-12 * (1.0 + t0.abs()));
        prop_assert!((back.grid().interval() - interval).abs() <= 1e-9 * interval);
        prop_assert_eq!(back.input_layout(), InputLayout::Piecewise);
        // With the experiment's grid, every instant's held input equals the input there.
        let held = record_from_table(&table, Some(&grid)).unwrap();
        for t in grid.times() {
            prop_assert_eq!(held.input().unwrap().value(t), input.value(t));
        }
        // The input file: switch times and levels exactly.
        let side = parse("r.input.csv", &input_to_csv(&input)).unwrap();
        let p = jitterid_study::csvio::input_from_table(&side, "t", "u", &grid).unwrap();
        prop_assert_eq!(p.edges(), input.edges());
        prop_assert_eq!(p.levels(), input.levels());
    }
}

#[test]
fn save_and_load_through_files() {
    let dir = scratch("files");
    let grid = SampleGrid::new(0.5, 0.25, 5).unwrap();
    let input = PiecewiseConstant::new(vec![0.0, 0.7, 3.0], vec![1.0, -2.0]).unwrap();
    let rec = MeasuredRecord::new(
        "a",
        Record::new(grid, vec![1.0, 2.0, 3.0, 4.0, 5.5]).unwrap(),
    )
    .with_input(Input::Piecewise(input.clone()))
    .with_noise_std(0.01)
    .unwrap();
    let path = dir.join("a.csv");
    save_record(&rec, &path).unwrap();
    let back = load_record(&path, None, Some(&grid)).unwrap();
    assert_eq!(back.y(), rec.y());
    assert_eq!(back.input(), rec.input());
    assert!(back.name().ends_with("a.csv"));
    assert_eq!(rec.noise_std(), Some(0.01));
    assert!(matches!(
        rec.clone().with_noise_std(-1.0),
        Err(jitterid::estimate::EstimateError::BadNoiseStd { .. })
    ));
}

fn line_col(e: &CsvError) -> (Option<usize>, Option<usize>) {
    (e.line(), e.column())
}

#[test]
fn malformed_files_name_the_line_and_the_column() {
    let e = parse("d.csv", "k,y\n0,1\n1,abc\n").unwrap_err();
    assert_eq!(line_col(&e), (Some(3), Some(3)));
    assert!(e.to_string().starts_with("d.csv:3:3: column `y`"), "{e}");
    let e = parse("d.csv", "k,y\n0,1,2\n").unwrap_err();
    assert_eq!(line_col(&e), (Some(2), Some(5)));
    // A record needs `y`, rows in order, instants on one grid.
    let t = parse("d.csv", "k,t\n0,0\n1,1\n").unwrap();
    let e = record_from_table(&t, None).unwrap_err();
    assert!(e.to_string().contains("expected a column named `y`"), "{e}");
    let t = parse("d.csv", "k,y\n0,1\n2,1\n").unwrap();
    let grid = SampleGrid::new(0.0, 1.0, 2).unwrap();
    let e = record_from_table(&t, Some(&grid)).unwrap_err();
    assert_eq!(e.line(), Some(3));
    assert!(e.to_string().contains("column `k`"), "{e}");
    let t = parse("d.csv", "t,y\n0,1\n1,1\n2.5,1\n").unwrap();
    let e = record_from_table(&t, None).unwrap_err();
    assert_eq!(e.line(), Some(3));
    assert!(e.to_string().contains("column `t`"), "{e}");
    let t = parse("d.csv", "y\n1\n2\n").unwrap();
    let e = record_from_table(&t, None).unwrap_err();
    assert!(e.to_string().contains("no column `t`"), "{e}");
    let e = record_from_table(&t, Some(&SampleGrid::new(0.0, 1.0, 3).unwrap())).unwrap_err();
    assert!(e.to_string().contains("expected 3"), "{e}");
    // An input file whose times go back.
    let t = parse("u.csv", "t,u\n0,1\n2,0.5\n1,0\n").unwrap();
    let e = jitterid_study::csvio::input_from_table(&t, "t", "u", &grid).unwrap_err();
    assert_eq!(e.line(), Some(4));
    // A file that is not there.
    let e = load_record(&scratch("none").join("none.csv"), None, None).unwrap_err();
    assert!(matches!(e, CsvError::Io { .. }));
    assert!(
        e.to_string().contains("cannot read: file does not exist"),
        "{e}"
    );
}

#[test]
fn a_model_is_evaluated_on_another_records_input() {
    let spec = serde_json::json!({"kind": "tf", "num": [1.0], "den": [1.0, 2.0]});
    let a = Input::Piecewise(PiecewiseConstant::new(vec![0.0, 5.0], vec![1.0]).unwrap());
    let b = Input::Piecewise(PiecewiseConstant::new(vec![2.0, 9.0], vec![3.0]).unwrap());
    let registry = SignalRegistry::builtin();
    let on_a = registry.build(spec.as_object().unwrap(), Some(&a)).unwrap();
    let fitted = on_a.with_params(&[2.0, 4.0]).unwrap();
    let moved = fitted.with_input(&b).unwrap();
    assert_eq!(moved.params(), fitted.params());
    let direct = registry.build(&fitted.spec(), Some(&b)).unwrap();
    for t in [0.0, 1.5, 2.5, 4.0, 8.0, 12.0] {
        assert_eq!(moved.value(t), direct.value(t));
    }
    // 2/(s+4) driven by 3 from t = 2 on: 1.5 (1 − e^{−4(t−2)}) before the input ends at 9.
    let t = 4.0f64;
    let expected = 1.5 * (1.0 - (-4.0 * (t - 2.0)).exp());
    assert!(
        (moved.value(t) - expected).abs() < 1e-12,
        "{}",
        moved.value(t)
    );
    assert_eq!(moved.value(1.0), 0.0);
}
