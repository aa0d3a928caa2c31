//! Issue 9, class by class, against the real binary: squeal never loses a
//! user's file, never hangs, never panics, and says what is wrong.

use std::path::Path;
use std::process::{Child, Command, ExitStatus, Output, Stdio};
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_squeal");

fn squeal(dir: &Path, args: &[&str]) -> Output {
    Command::new(BIN)
        .current_dir(dir)
        .args(args)
        .output()
        .expect("squeal runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Staging entries squeal left in `dir`.
fn leftovers(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".squeal-"))
        .collect()
}

/// Wait for a child at most `limit`; a child still running then is killed
/// and the test fails: it hung.
fn wait_at_most(child: &mut Child, limit: Duration, what: &str) -> ExitStatus {
    let start = Instant::now();
    loop {
        if let Some(s) = child.try_wait().unwrap() {
            return s;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{what}: still running after {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Run squeal, failing the test if it has not ended within `limit`.
fn ends_within(dir: &Path, args: &[&str], limit: Duration) -> Output {
    let mut child = Command::new(BIN)
        .current_dir(dir)
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    wait_at_most(&mut child, limit, &args.join(" "));
    child.wait_with_output().unwrap()
}

fn assert_refused(o: &Output, code: i32, needles: &[&str]) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(code), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
    assert!(!err.contains("panicked"), "{err}");
    for n in needles {
        assert!(err.contains(n), "'{n}' not in: {err}");
    }
}

// ---- Never lose or overwrite what squeal did not write ----

#[test]
fn a_rerun_keeps_a_users_file() {
    let d = tempfile::tempdir().unwrap();
    let args = [
        "simulate",
        "--duration",
        "0.002",
        "--out",
        "run",
        "--no-plots",
    ];
    assert!(squeal(d.path(), &args).status.success());
    let manifest = std::fs::read_to_string(d.path().join("run/.squeal-manifest.json")).unwrap();
    assert!(manifest.contains("series.csv") && manifest.contains("summary.json"));
    let before = std::fs::read(d.path().join("run/series.csv")).unwrap();
    std::fs::write(d.path().join("run/note.txt"), "my notes").unwrap();
    let o = squeal(d.path(), &args);
    assert_refused(&o, 2, &["note.txt", "--out"]);
    assert_eq!(
        std::fs::read_to_string(d.path().join("run/note.txt")).unwrap(),
        "my notes"
    );
    assert_eq!(
        std::fs::read(d.path().join("run/series.csv")).unwrap(),
        before
    );
    // Moved out of the way, the rerun replaces squeal's own files.
    std::fs::rename(d.path().join("run/note.txt"), d.path().join("note.txt")).unwrap();
    assert!(squeal(d.path(), &args).status.success());
    assert!(leftovers(d.path()).is_empty(), "{:?}", leftovers(d.path()));
}

#[test]
fn a_folder_with_a_report_but_no_manifest_is_refused() {
    let d = tempfile::tempdir().unwrap();
    let thesis = d.path().join("thesis");
    std::fs::create_dir(&thesis).unwrap();
    std::fs::write(thesis.join("report.md"), "# mine").unwrap();
    std::fs::write(thesis.join("main.c"), "int main;").unwrap();
    for args in [
        vec!["simulate", "--duration", "0.001", "--out", "thesis"],
        vec![
            "map",
            "--x",
            "N=100:200:2",
            "--y",
            "V=1:2:2",
            "--out",
            "thesis",
        ],
    ] {
        let o = squeal(d.path(), &args);
        assert_refused(&o, 2, &["thesis", ".squeal-manifest.json", "main.c"]);
    }
    assert_eq!(
        std::fs::read_to_string(thesis.join("main.c")).unwrap(),
        "int main;"
    );
    assert_eq!(
        std::fs::read_to_string(thesis.join("report.md")).unwrap(),
        "# mine"
    );
}

#[test]
fn a_scenario_name_is_a_name_not_a_path() {
    let d = tempfile::tempdir().unwrap();
    let work = d.path().join("work");
    std::fs::create_dir(&work).unwrap();
    let abs = d.path().join("abs").display().to_string();
    for name in [
        "../x",
        abs.as_str(),
        "",
        ".",
        "..",
        "a\\u0007b",
        "out/deeper",
    ] {
        std::fs::write(
            work.join("s.toml"),
            format!("name = \"{name}\"\nduration = 0.001\n"),
        )
        .unwrap();
        let o = squeal(&work, &["simulate", "s.toml"]);
        assert_refused(&o, 2, &["name"]);
    }
    let o = squeal(
        &work,
        &["simulate", "--set", "name=../x", "--duration", "0.001"],
    );
    assert_refused(&o, 2, &["name"]);
    assert!(!d.path().join("x").exists() && !d.path().join("abs").exists());
    assert!(!work.join("out").exists(), "nothing written");
}

#[test]
fn listen_never_overwrites_a_users_file_and_links_are_refused() {
    let d = tempfile::tempdir().unwrap();
    assert!(squeal(
        d.path(),
        &["simulate", "--duration", "0.01", "--out", "r", "--no-plots"]
    )
    .status
    .success());
    std::fs::write(d.path().join("notes.txt"), "keep me").unwrap();
    let o = squeal(d.path(), &["listen", "r", "--out", "notes.txt"]);
    assert_refused(&o, 2, &["notes.txt", "--force"]);
    assert_eq!(
        std::fs::read_to_string(d.path().join("notes.txt")).unwrap(),
        "keep me"
    );
    // A new name works; the same name again needs --force.
    assert!(squeal(d.path(), &["listen", "r", "--out", "a.wav"])
        .status
        .success());
    assert_refused(
        &squeal(d.path(), &["listen", "r", "--out", "a.wav"]),
        2,
        &["a.wav"],
    );
    assert!(
        squeal(d.path(), &["listen", "r", "--out", "a.wav", "--force"])
            .status
            .success()
    );
    // Links, to a file or to a folder, are not written through or replaced.
    std::os::unix::fs::symlink("notes.txt", d.path().join("link.wav")).unwrap();
    std::os::unix::fs::symlink("r", d.path().join("linkdir")).unwrap();
    let o = squeal(d.path(), &["listen", "r", "--out", "link.wav", "--force"]);
    assert_refused(&o, 2, &["link.wav", "link"]);
    let o = squeal(
        d.path(),
        &["simulate", "--duration", "0.001", "--out", "linkdir"],
    );
    assert_refused(&o, 2, &["linkdir", "link"]);
    assert!(std::fs::symlink_metadata(d.path().join("linkdir"))
        .unwrap()
        .file_type()
        .is_symlink());
    assert_eq!(
        std::fs::read_to_string(d.path().join("notes.txt")).unwrap(),
        "keep me"
    );
    assert!(leftovers(d.path()).is_empty(), "{:?}", leftovers(d.path()));
}

/// SIGINT and SIGTERM while the output is being written: exit 130/143 and
/// no staging folder, no destination.
#[test]
fn an_interrupt_while_writing_leaves_nothing_behind() {
    for (sig, code) in [("-INT", 130), ("-TERM", 143)] {
        let d = tempfile::tempdir().unwrap();
        let mut child = Command::new(BIN)
            .current_dir(d.path())
            .args(["simulate", "--duration", "3", "--out", "big"])
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // Wait until the series is being written into the staging folder.
        let start = Instant::now();
        loop {
            let writing = leftovers(d.path())
                .iter()
                .any(|s| d.path().join(s).join("series.csv").exists());
            if writing {
                break;
            }
            assert!(child.try_wait().unwrap().is_none(), "ended before writing");
            assert!(start.elapsed() < Duration::from_secs(120), "never wrote");
            std::thread::sleep(Duration::from_millis(5));
        }
        let killed = Command::new("kill")
            .args([sig, &child.id().to_string()])
            .status()
            .unwrap();
        assert!(killed.success());
        let status = wait_at_most(&mut child, Duration::from_secs(30), "interrupted run");
        assert_eq!(status.code(), Some(code), "{sig}");
        assert!(leftovers(d.path()).is_empty(), "{:?}", leftovers(d.path()));
        assert!(!d.path().join("big").exists());
    }
}

#[test]
fn stale_staging_of_a_dead_run_does_not_block_the_next() {
    let d = tempfile::tempdir().unwrap();
    // A PID that surely is no longer running: a child that has ended.
    let mut gone = Command::new("true").spawn().unwrap();
    gone.wait().unwrap();
    let pid = gone.id();
    // A partial staging folder (no manifest) and a swapped-out old output
    // (with a manifest) of that dead run, beside the destination.
    let partial = d.path().join(format!(".squeal-{pid}-0123456789abcdef.new"));
    std::fs::create_dir(&partial).unwrap();
    // squeal marks the staging folders it makes with its pid (issue 24:
    // one without the marker is not squeal's and is never deleted).
    std::fs::write(
        partial.join(".squeal-staging.json"),
        format!(r#"{{"written_by": "squeal", "pid": {pid}}}"#),
    )
    .unwrap();
    std::fs::write(partial.join("series.csv"), vec![b'1'; 1 << 20]).unwrap();
    let old = d.path().join(format!(".squeal-{pid}-0123456789abcdef.old"));
    std::fs::create_dir(&old).unwrap();
    std::fs::write(old.join("summary.json"), "{}").unwrap();
    std::fs::write(
        old.join(".squeal-manifest.json"),
        r#"{"written_by": "squeal", "files": ["summary.json"]}"#,
    )
    .unwrap();
    let o = squeal(
        d.path(),
        &[
            "simulate",
            "--duration",
            "0.001",
            "--out",
            "run",
            "--no-plots",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(leftovers(d.path()).is_empty(), "{:?}", leftovers(d.path()));
    assert!(d.path().join("run/summary.json").is_file());
}

#[test]
fn long_names_work_and_an_unwritable_place_is_found_before_the_work() {
    let d = tempfile::tempdir().unwrap();
    let long = "r".repeat(255);
    let o = squeal(
        d.path(),
        &[
            "simulate",
            "--duration",
            "0.001",
            "--out",
            &long,
            "--no-plots",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(d.path().join(&long).join("series.csv").is_file());
    // A destination below a file cannot be created: found at once, before
    // a run that would take minutes.
    std::fs::write(d.path().join("plain"), "x").unwrap();
    let o = ends_within(
        d.path(),
        &["simulate", "--duration", "30", "--out", "plain/run"],
        Duration::from_secs(30),
    );
    assert!(matches!(o.status.code(), Some(1 | 2)), "{}", stderr(&o));
    assert!(stderr(&o).contains("plain"), "{}", stderr(&o));
}

// ---- Never hang, never crash, never answer wrong in silence ----

#[test]
fn extreme_parameters_end_within_seconds_naming_the_cause() {
    let d = tempfile::tempdir().unwrap();
    let cases: [(&[&str], &str); 5] = [
        (&["simulate", "--set", "c_dx=1e15"], "c_dx"),
        (&["simulate", "--set", "V=1e15"], "V"),
        (&["simulate", "--set", "Uc=1e-12"], "Uc"),
        (&["simulate", "belt", "--set", "c=1e15"], "c"),
        (&["simulate", "hoffmann", "--set", "m=1e-12"], "m"),
    ];
    for (args, param) in cases {
        let o = ends_within(d.path(), args, Duration::from_secs(60));
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(
            err.contains(&format!("set by {param} = ")) && err.contains("stiff"),
            "{args:?}: {err}"
        );
        assert!(err.contains("time scale") && err.contains("steps"), "{err}");
        // The parameter ratio behind the time scale, e.g. |λ| ∝ c_dx^1 · m_d^-1.
        assert!(
            err.contains(&format!("{param}^")) && err.contains("∝"),
            "{err}"
        );
    }
    assert!(!d.path().join("out").exists(), "nothing written");
}

#[test]
fn non_finite_linearisations_are_errors_that_end() {
    let d = tempfile::tempdir().unwrap();
    for args in [
        vec!["stability", "--set", "Uc=1e-300"],
        vec!["simulate", "--set", "Uc=1e-300"],
        vec!["critical", "--param", "Uc=1e-300:1"],
        vec![
            "map",
            "--x",
            "Uc=1e-300:1:2",
            "--y",
            "N=100:200:2",
            "--out",
            "m",
        ],
    ] {
        let o = ends_within(d.path(), &args, Duration::from_secs(60));
        assert_refused(&o, 2, &["Uc", "not finite"]);
    }
    assert!(!d.path().join("m").exists());
    // A scan that would not end in a lifetime is refused.
    let o = squeal(
        d.path(),
        &["critical", "--param", "c_dx=0:10", "--grid", "100000000000"],
    );
    assert_refused(&o, 2, &["--grid"]);
}

#[test]
fn every_simulating_command_is_validated_the_same_way() {
    let d = tempfile::tempdir().unwrap();
    let sim = squeal(d.path(), &["simulate", "--duration", "1e9"]);
    let map = squeal(
        d.path(),
        &[
            "map",
            "--x",
            "N=100:200:2",
            "--y",
            "V=1:2:2",
            "--transient",
            "--duration",
            "1e9",
        ],
    );
    let listen = squeal(d.path(), &["listen", "--set", "duration=1e9"]);
    for o in [&sim, &map, &listen] {
        assert_refused(o, 2, &["1e9", "samples"]);
    }
    // What the refusal says is the same, whichever command.
    assert_eq!(stderr(&sim), stderr(&map));
    // Within the sample limit but beyond memory: refused with the size.
    let sim = squeal(d.path(), &["simulate", "--duration", "60"]);
    let map = squeal(
        d.path(),
        &[
            "map",
            "--x",
            "N=100:200:2",
            "--y",
            "V=1:2:2",
            "--transient",
            "--duration",
            "60",
        ],
    );
    for o in [&sim, &map] {
        assert_refused(o, 2, &["sample_rate", "1.25 GB in memory", "limit"]);
    }
    assert!(!d.path().join("out").exists());
}

#[test]
fn an_under_resolved_sample_rate_is_refused_with_the_least_that_works() {
    let d = tempfile::tempdir().unwrap();
    let o = squeal(d.path(), &["simulate", "--set", "sample_rate=1"]);
    assert_refused(&o, 2, &["sample_rate", "least rate"]);
    // The least rate is twice the fastest mode (34 412.35 Hz, MODEL.md §5).
    let err = stderr(&o);
    let least: f64 = err
        .rsplit("is ")
        .next()
        .unwrap()
        .trim()
        .trim_end_matches("Hz")
        .trim()
        .parse()
        .unwrap_or_else(|_| panic!("{err}"));
    assert!((least / (2.0 * 34412.35) - 1.0).abs() < 1e-6, "{least}");
    // Just below is refused, just above runs.
    let below = format!("sample_rate={}", least * 0.999);
    let above = format!("sample_rate={}", least * 1.001);
    assert_refused(
        &squeal(
            d.path(),
            &["simulate", "--set", &below, "--duration", "0.002"],
        ),
        2,
        &["sample_rate"],
    );
    let o = squeal(
        d.path(),
        &[
            "simulate",
            "--set",
            &above,
            "--duration",
            "0.002",
            "--no-plots",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn plot_and_listen_survive_any_numbers() {
    let d = tempfile::tempdir().unwrap();
    assert!(squeal(
        d.path(),
        &["simulate", "--duration", "0.01", "--out", "r", "--no-plots"]
    )
    .status
    .success());
    let series = std::fs::read_to_string(d.path().join("r/series.csv")).unwrap();
    let edit = |name: &str, row: usize, col: usize, value: &str| {
        std::fs::create_dir(d.path().join(name)).unwrap();
        for f in ["summary.json", "events.csv", ".squeal-manifest.json"] {
            std::fs::copy(d.path().join("r").join(f), d.path().join(name).join(f)).unwrap();
        }
        let mut lines: Vec<String> = series.lines().map(String::from).collect();
        let mut cells: Vec<&str> = lines[row].split(',').collect();
        cells[col] = value;
        lines[row] = cells.join(",");
        std::fs::write(d.path().join(name).join("series.csv"), lines.join("\n")).unwrap();
    };
    edit("huge", 100, 5, "1.7e308");
    edit("nan", 50, 3, "NaN");
    edit("inf", 50, 6, "-inf");
    edit("back", 30, 0, "0");
    for dir in ["huge", "nan", "inf", "back"] {
        for cmd in ["plot", "listen"] {
            let wav = format!("{dir}.wav");
            let args = if cmd == "plot" {
                vec!["plot", dir]
            } else {
                vec!["listen", dir, "--out", &wav]
            };
            let o = ends_within(d.path(), &args, Duration::from_secs(60));
            let err = stderr(&o);
            assert!(!err.contains("panicked"), "{args:?}: {err}");
            if dir != "huge" {
                assert_refused(&o, 2, &[dir]);
            }
        }
    }
    assert!(stderr(&squeal(d.path(), &["plot", "nan"])).contains("not a finite number"));
    assert!(stderr(&squeal(d.path(), &["plot", "back"])).contains("t must increase"));
    // A run folder with a header and no rows.
    std::fs::create_dir(d.path().join("empty")).unwrap();
    std::fs::copy(
        d.path().join("r/summary.json"),
        d.path().join("empty/summary.json"),
    )
    .unwrap();
    std::fs::write(
        d.path().join("empty/series.csv"),
        series.lines().next().unwrap(),
    )
    .unwrap();
    let o = squeal(d.path(), &["plot", "empty"]);
    assert_refused(&o, 2, &["empty", "no samples"]);
}

#[test]
fn a_closed_or_full_stdout_is_not_a_panic() {
    let d = tempfile::tempdir().unwrap();
    for args in [
        vec!["stability"],
        vec!["scenario", "show", "disc-pad"],
        vec!["simulate", "--duration", "0.001", "--no-plots", "--json"],
    ] {
        // The reader is gone before squeal writes (like `| true`).
        let mut child = Command::new(BIN)
            .current_dir(d.path())
            .args(&args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        drop(child.stdout.take());
        let o = child.wait_with_output().unwrap();
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(0), "{args:?}: {err}");
        assert!(err.is_empty(), "quiet on a broken pipe: {err}");
        // A full disk behind stdout: one line, exit 1.
        let full = std::fs::File::create("/dev/full").unwrap();
        let o = Command::new(BIN)
            .current_dir(d.path())
            .args(&args)
            .stdout(full)
            .output()
            .unwrap();
        assert_refused(&o, 1, &["standard output"]);
    }
}

#[test]
fn reproduce_twice_gives_byte_identical_reports() {
    let d = tempfile::tempdir().unwrap();
    for out in ["a", "b"] {
        let o = squeal(
            d.path(),
            &["reproduce", "--out", out, "--duration-scale", "0.05"],
        );
        assert!(o.status.success(), "{}", stderr(&o));
    }
    // Every file, figures included, byte for byte.
    fn files(root: &Path, dir: &Path, out: &mut Vec<std::path::PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                files(root, &p, out);
            } else {
                out.push(p.strip_prefix(root).unwrap().to_path_buf());
            }
        }
    }
    let (mut fa, mut fb) = (Vec::new(), Vec::new());
    files(&d.path().join("a"), &d.path().join("a"), &mut fa);
    files(&d.path().join("b"), &d.path().join("b"), &mut fb);
    fa.sort();
    fb.sort();
    assert_eq!(fa, fb);
    for f in ["report.md", "report.html", "table.csv", "conclusions.json"] {
        assert!(fa.contains(&f.into()), "{f} missing");
    }
    for f in &fa {
        let a = std::fs::read(d.path().join("a").join(f)).unwrap();
        let b = std::fs::read(d.path().join("b").join(f)).unwrap();
        assert!(a == b, "{} differs between two identical runs", f.display());
    }
}

// ---- Messages that help ----

#[test]
fn messages_name_the_fix() {
    let d = tempfile::tempdir().unwrap();
    let o = squeal(d.path(), &["simulate", "--set", "V", "2"]);
    assert_refused(&o, 2, &["--set needs NAME=VALUE", "--set V=2"]);
    let o = squeal(d.path(), &["simulate", "--overlap", "-0.1"]);
    assert_refused(&o, 2, &["--overlap", "-0.1"]);
    let o = squeal(d.path(), &["simulate", "--no-such-flag"]);
    assert_refused(&o, 2, &["--no-such-flag"]);
    let o = squeal(d.path(), &["simulate", "--set", "n=2"]);
    assert_refused(&o, 2, &["'n'", "did you mean 'N'"]);
    let o = squeal(d.path(), &["simulate", "--set", "zzz=2"]);
    assert_refused(&o, 2, &["'zzz'", "valid keys", "k_dx", "f0"]);
    // Not a scenario: a device is refused by name, not read (issue 24).
    std::os::unix::fs::symlink("/dev/zero", d.path().join("zero.toml")).unwrap();
    let o = ends_within(
        d.path(),
        &["simulate", "zero.toml"],
        Duration::from_secs(30),
    );
    assert_refused(&o, 2, &["zero.toml", "is a character device"]);
    // μ = 0 is a friction coefficient; an invalid endpoint is named.
    let o = squeal(d.path(), &["critical", "hoffmann", "--param", "mu=0:1"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = squeal(d.path(), &["critical", "hoffmann", "--param", "mu=-1:1"]);
    assert_refused(&o, 2, &["--param", "LO = -1", "mu"]);
    let o = squeal(
        d.path(),
        &["map", "--x", "N=100:200:2", "--y", "V=1:-2:2", "--out", "m"],
    );
    assert_refused(&o, 2, &["--y"]);
    let o = squeal(
        d.path(),
        &[
            "map",
            "hoffmann",
            "--x",
            "mu=0:0.5:2",
            "--y",
            "k3=-5:1:2",
            "--out",
            "m",
        ],
    );
    assert_refused(&o, 2, &["--y", "LO = -5", "k3"]);
}

#[test]
fn plot_replaces_only_files_squeal_wrote() {
    let d = tempfile::tempdir().unwrap();
    let sim = ["simulate", "--duration", "0.01", "--out", "r", "--no-plots"];
    assert!(squeal(d.path(), &sim).status.success());
    // The pictures are new files: plot adds them and lists them.
    let o = squeal(d.path(), &["plot", "r"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let manifest = std::fs::read_to_string(d.path().join("r/.squeal-manifest.json")).unwrap();
    assert!(manifest.contains("triplet.png"), "{manifest}");
    assert!(squeal(d.path(), &["plot", "r", "--window", "flattop"])
        .status
        .success());
    // A user's picture where plot would write one is not replaced.
    assert!(squeal(
        d.path(),
        &["simulate", "--duration", "0.01", "--out", "s", "--no-plots"]
    )
    .status
    .success());
    std::fs::write(d.path().join("s/phase.png"), "my drawing").unwrap();
    let o = squeal(d.path(), &["plot", "s"]);
    assert_refused(&o, 2, &["phase.png"]);
    assert_eq!(
        std::fs::read_to_string(d.path().join("s/phase.png")).unwrap(),
        "my drawing"
    );
    assert!(leftovers(d.path()).is_empty(), "{:?}", leftovers(d.path()));
}

/// Concurrent writers to one destination: every run succeeds, the last
/// swap wins, and nothing is left behind.
#[test]
fn concurrent_runs_into_one_folder_all_succeed() {
    let d = tempfile::tempdir().unwrap();
    let children: Vec<Child> = (0..4)
        .map(|_| {
            Command::new(BIN)
                .current_dir(d.path())
                .args([
                    "simulate",
                    "--duration",
                    "0.005",
                    "--out",
                    "same",
                    "--no-plots",
                ])
                .stdout(Stdio::null())
                .stderr(Stdio::piped())
                .spawn()
                .unwrap()
        })
        .collect();
    for c in children {
        let o = c.wait_with_output().unwrap();
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let manifest = std::fs::read_to_string(d.path().join("same/.squeal-manifest.json")).unwrap();
    assert!(manifest.contains("series.csv"));
    assert_eq!(
        std::fs::read_to_string(d.path().join("same/series.csv"))
            .unwrap()
            .lines()
            .count(),
        1 + 1001
    );
    assert!(leftovers(d.path()).is_empty(), "{:?}", leftovers(d.path()));
}
