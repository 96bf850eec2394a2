//! The output set's tests: every destination kind, the lock, the recovery after a kill at
//! every point of a commit, and the refusals.

use super::*;

#[cfg(unix)]
#[test]
fn devices_are_written_through_and_directories_refused() {
    // Classification only: nothing is written to the device.
    assert_eq!(
        target_of(Path::new("/dev/null"), "null").unwrap(),
        Target::Stream(PathBuf::from("/dev/null"))
    );
    assert!(writes_through(Path::new("/dev/null")));
    let e = target_of(Path::new("/"), "/").unwrap_err();
    assert!(e.message().contains("is a directory"), "{e}");
    let missing = Path::new("/no/such/file.csv");
    assert_eq!(
        target_of(missing, "x").unwrap(),
        Target::Replace(missing.to_path_buf())
    );
}

fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// A failure after the checks (a destination changed meanwhile) rolls back the renames.
#[test]
fn a_late_failure_restores_the_files_already_renamed() {
    let dir = tempfile::tempdir().unwrap();
    let (old, new, blocked) = (
        dir.path().join("old.csv"),
        dir.path().join("new.csv"),
        dir.path().join("blocked"),
    );
    std::fs::write(&old, "previous").unwrap();
    // A non-empty directory cannot be renamed over; it stands for a target that became
    // one after the checks.
    std::fs::create_dir(&blocked).unwrap();
    std::fs::write(blocked.join("inside"), "x").unwrap();
    let files = vec![
        (old.clone(), b"replaced".to_vec()),
        (new.clone(), b"created".to_vec()),
        (blocked.clone(), b"never".to_vec()),
    ];
    let targets: Vec<Target> = files
        .iter()
        .map(|(p, _)| Target::Replace(p.clone()))
        .collect();
    let e = write_all(&files, &targets).unwrap_err();
    assert!(e.message().contains("blocked"), "{e}");
    assert_eq!(std::fs::read_to_string(&old).unwrap(), "previous");
    assert_eq!(names(dir.path()), ["blocked", "old.csv"]);
    // A stream that cannot be opened rolls back the renamed files too.
    let files = vec![
        (old.clone(), b"replaced".to_vec()),
        (dir.path().join("pipe"), b"never".to_vec()),
    ];
    let targets = vec![
        Target::Replace(old.clone()),
        Target::Stream(dir.path().join("no/such/pipe")),
    ];
    assert!(write_all(&files, &targets).is_err());
    assert_eq!(std::fs::read_to_string(&old).unwrap(), "previous");
    assert_eq!(names(dir.path()), ["blocked", "old.csv"]);
    // And when nothing fails, every file is there.
    let files = vec![
        (old.clone(), b"replaced".to_vec()),
        (new.clone(), b"created".to_vec()),
    ];
    let targets: Vec<Target> = files
        .iter()
        .map(|(p, _)| Target::Replace(p.clone()))
        .collect();
    write_all(&files, &targets).unwrap();
    assert_eq!(std::fs::read_to_string(&old).unwrap(), "replaced");
    assert_eq!(std::fs::read_to_string(&new).unwrap(), "created");
    assert_eq!(names(dir.path()), ["blocked", "new.csv", "old.csv"]);
}

#[test]
fn a_file_written_twice_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let mut set = OutputSet::new();
    set.file(&dir.path().join("a.svg"), "one");
    set.file(&dir.path().join("./a.svg"), "two");
    let e = set.commit().unwrap_err();
    assert!(e.message().contains("twice"), "{e}");
    assert!(names(dir.path()).is_empty());
}

#[test]
fn a_figure_directory_is_removed_again_when_the_set_fails() {
    let dir = tempfile::tempdir().unwrap();
    let figs = dir.path().join("figs/deeper");
    let mut set = OutputSet::new();
    set.dir(&figs);
    set.file(&figs.join("a.svg"), "<svg/>");
    set.file(&dir.path().join("nodir/r.json"), "{}");
    let e = set.commit().unwrap_err();
    assert!(e.message().contains("does not exist"), "{e}");
    assert!(names(dir.path()).is_empty(), "{:?}", names(dir.path()));
}

/// The race of the old design, made deterministic: it created `.backup.XXXX.tmp`, unlinked
/// it, then linked or else *copied* the old output to that name; a symbolic link planted
/// there in between sent the old contents to the link's target. Here the name the set
/// would use is planted first, with a link to a victim file: the link is never written
/// through (`link` fails on an existing name and another name is drawn), the victim is
/// untouched, and the set is written.
#[cfg(unix)]
#[test]
fn a_link_planted_where_the_old_file_is_kept_is_never_written_through() {
    let dir = tempfile::tempdir().unwrap();
    let (out, victim) = (dir.path().join("out.csv"), dir.path().join("victim"));
    std::fs::write(&out, "old output").unwrap();
    std::fs::write(&victim, "precious").unwrap();
    let planted = dir.path().join(".out.csv.jitterid-old-1-0000000000000000");
    std::os::unix::fs::symlink(&victim, &planted).unwrap();
    let mut first = true;
    let mut names = |t: &Path, k: Kind| {
        if k == Kind::Linked && std::mem::take(&mut first) {
            planted.clone()
        } else {
            fresh_name(t, k)
        }
    };
    let files = vec![(out.clone(), b"new output".to_vec())];
    let targets = vec![Target::Replace(out.clone())];
    write_all_with(&files, &targets, &mut names, READER_WAIT, None).unwrap();
    assert!(!first, "the planted name was tried");
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious");
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "new output");
    assert!(std::fs::symlink_metadata(&planted)
        .unwrap()
        .file_type()
        .is_symlink());
    // The fallback where there are no hard links renames the old file over the name: the
    // link is replaced, not followed.
    let mut names = |_: &Path, _: Kind| planted.clone();
    let (aside, kind) = keep_aside(&out, &mut names, false).unwrap();
    assert_eq!((aside.as_path(), kind), (planted.as_path(), Kind::Moved));
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious");
    assert_eq!(std::fs::read_to_string(&planted).unwrap(), "new output");
    assert!(!out.exists());
    std::fs::remove_file(&aside).unwrap();
    assert!(!planted.exists() && victim.exists());
}

/// Two sets committed to the same files from two threads at once: each ends whole (the data
/// file and its side file from the same writer), never one run's file beside the other's,
/// and no temporary stays behind.
#[test]
fn two_writers_of_the_same_files_never_leave_a_mixed_set() {
    let dir = tempfile::tempdir().unwrap();
    let (data, side) = (dir.path().join("d.csv"), dir.path().join("d.input.csv"));
    for round in 0..40 {
        let barrier = std::sync::Barrier::new(2);
        std::thread::scope(|s| {
            for who in ["A", "B"] {
                let (data, side, barrier) = (&data, &side, &barrier);
                s.spawn(move || {
                    let mut set = OutputSet::new();
                    // Large enough that the writes take a while.
                    set.file(data, format!("{who}{round}").repeat(20_000));
                    set.file(side, format!("{who}{round}"));
                    barrier.wait();
                    set.commit().unwrap();
                });
            }
        });
        let (d, s) = (
            std::fs::read_to_string(&data).unwrap(),
            std::fs::read_to_string(&side).unwrap(),
        );
        assert_eq!(d, s.repeat(20_000), "round {round}: a mixed set");
        assert_eq!(names(dir.path()), ["d.csv", "d.input.csv"]);
    }
}

/// A commit stopped at each point where a kill could stop it, over a set spread on two
/// directories (a data file and its side file, and a figure elsewhere): the next commit in
/// either directory leaves the set all old (killed before the journal was written, or
/// while undoing after an error) or all new (killed during or after the renames), never
/// mixed, and no temporary or journal stays behind.
#[test]
fn a_kill_at_any_point_of_a_commit_leaves_a_set_the_next_run_makes_whole() {
    use KillPoint::*;
    let cases = [
        (BeforeJournal, "old"),
        (AfterRenames(0), "new"),
        (AfterRenames(1), "new"),
        (AfterRenames(2), "new"),
        (AfterRenames(3), "new"),
        (AfterJournal, "new"),
        (WhileUndoing(0), "old"),
        (WhileUndoing(2), "old"),
    ];
    for (kill, expected) in cases {
        let root = tempfile::tempdir().unwrap();
        let (dir, figs) = (root.path().join("out"), root.path().join("figs"));
        std::fs::create_dir(&dir).unwrap();
        std::fs::create_dir(&figs).unwrap();
        let set = [
            dir.join("d.csv"),
            dir.join("d.input.csv"),
            figs.join("f.svg"),
        ];
        let mut old = OutputSet::new();
        for p in &set {
            old.file(p, "old");
        }
        old.commit().unwrap();
        let mut files: Vec<(PathBuf, Vec<u8>)> =
            set.iter().map(|p| (p.clone(), b"new".to_vec())).collect();
        if matches!(kill, WhileUndoing(_)) {
            // A non-empty directory cannot be renamed over: the last rename fails, and the
            // commit undoes the three before it.
            let blocked = dir.join("blocked");
            std::fs::create_dir(&blocked).unwrap();
            std::fs::write(blocked.join("inside"), "x").unwrap();
            files.push((blocked, b"never".to_vec()));
        }
        let targets: Vec<Target> = files
            .iter()
            .map(|(p, _)| Target::Replace(p.clone()))
            .collect();
        let e =
            write_all_with(&files, &targets, &mut fresh_name, READER_WAIT, Some(kill)).unwrap_err();
        assert!(e.message().contains("kill"), "{kill:?}: {e}");
        // The next commit, writing into the figure directory only.
        lock_and_clean(&[Target::Replace(figs.join("other.svg"))]).unwrap();
        let now: Vec<String> = set
            .iter()
            .map(|p| std::fs::read_to_string(p).unwrap())
            .collect();
        assert_eq!(now, [expected; 3], "{kill:?}");
        // And one in the other: nothing of the killed commit is left.
        lock_and_clean(&[Target::Replace(dir.join("other.csv"))]).unwrap();
        let mut want = vec!["d.csv", "d.input.csv"];
        if matches!(kill, WhileUndoing(_)) {
            want.insert(0, "blocked");
        }
        assert_eq!(names(&dir), want, "{kill:?}");
        assert_eq!(names(&figs), ["f.svg"], "{kill:?}");
    }
}

/// A recovery that is itself killed is taken up again by the next writer: a set killed
/// during its renames, then its recovery stopped half way (one staged file renamed by the
/// recovery, the journal still there), ends all new.
#[test]
fn a_recovery_killed_half_way_is_finished_by_the_next() {
    let dir = tempfile::tempdir().unwrap();
    let set = [dir.path().join("a.csv"), dir.path().join("b.csv")];
    let mut old = OutputSet::new();
    for p in &set {
        old.file(p, "old");
    }
    old.commit().unwrap();
    let files: Vec<(PathBuf, Vec<u8>)> = set.iter().map(|p| (p.clone(), b"new".to_vec())).collect();
    let targets: Vec<Target> = set.iter().map(|p| Target::Replace(p.clone())).collect();
    let kill = Some(KillPoint::AfterRenames(0));
    write_all_with(&files, &targets, &mut fresh_name, READER_WAIT, kill).unwrap_err();
    // What the recovery does first, by hand: the first staged file renamed into place.
    let staged: Vec<PathBuf> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_string_lossy().contains(".a.csv.jitterid-tmp-"))
        .collect();
    assert_eq!(staged.len(), 1);
    std::fs::rename(&staged[0], &set[0]).unwrap();
    lock_and_clean(&targets).unwrap();
    for p in &set {
        assert_eq!(std::fs::read_to_string(p).unwrap(), "new");
    }
    assert_eq!(names(dir.path()), ["a.csv", "b.csv"]);
}

/// Temporaries a killed writer left (named after a process that is gone) are removed by
/// the next commit in their directory; a replaced file moved aside whose file is missing (a
/// kill between the two renames) is put back; files that only look alike stay.
#[test]
fn stale_temporaries_of_a_dead_writer_are_cleaned() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path();
    // No process has this number (Linux's largest is 2^22).
    let dead = 999_999_999u32;
    let stale = [
        format!(".r.json.jitterid-tmp-{dead}-00000000deadbeef"),
        format!(".r.json.jitterid-old-{dead}-0123456789abcdef"),
    ];
    for n in &stale {
        std::fs::write(p.join(n), "stale").unwrap();
    }
    let moved = format!(".lost.csv.jitterid-moved-{dead}-fedcba9876543210");
    std::fs::write(p.join(&moved), "the previous lost.csv").unwrap();
    let alike = [
        ".r.json.jitterid-tmp-notapid-00000000deadbeef".to_string(),
        format!(".r.json.jitterid-tmp-{dead}-short"),
        "r.json.jitterid-tmp-1-0000000000000000".to_string(),
    ];
    for n in &alike {
        std::fs::write(p.join(n), "mine").unwrap();
    }
    assert_eq!(
        parse_temp(&stale[0]),
        Some((Kind::New, dead, "r.json".to_string()))
    );
    let mut set = OutputSet::new();
    set.file(&p.join("r.json"), "{}");
    set.commit().unwrap();
    let mut want: Vec<String> = alike.to_vec();
    want.extend(["lost.csv".to_string(), "r.json".to_string()]);
    want.sort();
    assert_eq!(names(p), want);
    assert_eq!(
        std::fs::read_to_string(p.join("lost.csv")).unwrap(),
        "the previous lost.csv"
    );
    // A file with a long name: its temporaries' names are shortened, and it is written.
    let long = p.join("x".repeat(240));
    let mut set = OutputSet::new();
    set.file(&long, "long");
    set.commit().unwrap();
    let mut set = OutputSet::new();
    set.file(&long, "longer");
    set.commit().unwrap();
    assert_eq!(std::fs::read_to_string(&long).unwrap(), "longer");
    std::fs::remove_file(&long).unwrap();
    // Without the lock (a directory that cannot be locked), only a dead writer's go.
    let live = format!(
        ".r.json.jitterid-tmp-{}-00000000deadbeef",
        std::process::id()
    );
    std::fs::write(p.join(&live), "in use").unwrap();
    std::fs::write(p.join(&stale[0]), "stale").unwrap();
    clean_stale(p, false);
    assert!(p.join(&live).exists() && !p.join(&stale[0]).exists());
}

/// A FIFO that no process reads: the write gives up after the wait, with an error, instead
/// of blocking for ever; what was renamed before it is rolled back.
#[cfg(unix)]
#[test]
fn a_fifo_without_a_reader_is_an_error_not_a_hang() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("pipe");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap();
    assert!(made.success());
    let data = dir.path().join("d.csv");
    std::fs::write(&data, "previous").unwrap();
    let files = vec![
        (data.clone(), b"new".to_vec()),
        (fifo.clone(), b"never read".to_vec()),
    ];
    let targets = vec![
        target_of(&data, "d").unwrap(),
        target_of(&fifo, "p").unwrap(),
    ];
    assert_eq!(targets[1], Target::Stream(fifo.clone()));
    // The result says the wait ended: the error is the one given when it runs out.
    let e = write_all_with(
        &files,
        &targets,
        &mut fresh_name,
        Duration::from_millis(200),
        None,
    )
    .unwrap_err();
    assert!(e.message().contains("no process is reading"), "{e}");
    assert_eq!(std::fs::read_to_string(&data).unwrap(), "previous");
    assert_eq!(names(dir.path()), ["d.csv", "pipe"]);
    // With a reader, the same FIFO is written.
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read_to_string(fifo).unwrap())
    };
    write_all_with(
        &files,
        &targets,
        &mut fresh_name,
        Duration::from_secs(30),
        None,
    )
    .unwrap();
    assert_eq!(reader.join().unwrap(), "never read");
    assert_eq!(std::fs::read_to_string(&data).unwrap(), "new");
}
