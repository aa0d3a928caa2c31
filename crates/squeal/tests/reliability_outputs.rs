//! Issue 24, classes 4, 5 and 6, against the real binary: outputs never
//! replace what squeal did not create (devices, links, folders named like
//! its staging), interrupts remove every folder the run made, a failed
//! write to stderr is not a panic, and error lines are fit for a terminal.

use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_squeal");

fn squeal(dir: &Path, args: &[&str]) -> Output {
    Command::new(BIN)
        .current_dir(dir)
        .args(args)
        .stdin(Stdio::null())
        .output()
        .expect("squeal runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn refused(o: &Output, needles: &[&str]) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(2), "exit 2 expected: {err}");
    for n in needles {
        assert!(err.contains(n), "{n:?} not in: {err}");
    }
}

fn mkfifo(p: &Path) {
    assert!(Command::new("mkfifo").arg(p).status().unwrap().success());
}

fn is_fifo(p: &Path) -> bool {
    use std::os::unix::fs::FileTypeExt;
    std::fs::symlink_metadata(p).is_ok_and(|m| m.file_type().is_fifo())
}

#[test]
fn listen_force_replaces_only_a_regular_file() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    let o = squeal(
        dir,
        &["simulate", "belt", "--duration", "0.05", "--out", "r"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    // A FIFO (standing in for a device): refused even with --force, and
    // still a FIFO afterwards (today it was replaced).
    mkfifo(&dir.join("pipe.wav"));
    let o = squeal(dir, &["listen", "r", "--out", "pipe.wav", "--force"]);
    refused(&o, &["pipe.wav", "is a pipe (FIFO), not a regular file"]);
    assert!(is_fifo(&dir.join("pipe.wav")));
    // A regular file is replaced with --force.
    std::fs::write(dir.join("old.wav"), "old").unwrap();
    let o = squeal(dir, &["listen", "r", "--out", "old.wav", "--force"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(std::fs::read(dir.join("old.wav"))
        .unwrap()
        .starts_with(b"RIFF"));
    // Nothing staged is left beside it.
    let left: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".squeal-"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
}

#[test]
fn plot_does_not_write_through_a_symlinked_run_folder() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    let o = squeal(
        dir,
        &["simulate", "belt", "--duration", "0.05", "--out", "real"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    std::os::unix::fs::symlink("real", dir.join("link")).unwrap();
    let before = std::fs::read(dir.join("real/summary.json")).unwrap();
    for arg in ["link", "link/"] {
        let o = squeal(dir, &["plot", arg, "--window", "hann"]);
        refused(&o, &["run folder link", "symbolic link"]);
    }
    assert_eq!(
        std::fs::read(dir.join("real/summary.json")).unwrap(),
        before
    );
    // A linked ancestor (a scratch folder reached through a link) is fine.
    std::fs::create_dir(dir.join("scratch")).unwrap();
    std::os::unix::fs::symlink("scratch", dir.join("s")).unwrap();
    let o = squeal(
        dir,
        &["simulate", "belt", "--duration", "0.05", "--out", "s/run"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let o = squeal(dir, &["plot", "s/run"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(dir.join("scratch/run/summary.json").is_file());
    // `--out link/` is the link, not the folder behind it.
    let o = squeal(
        dir,
        &["simulate", "belt", "--duration", "0.05", "--out", "link/"],
    );
    refused(&o, &["symbolic link"]);
}

#[test]
fn a_folder_merely_named_like_a_staging_folder_is_never_deleted() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    // A dead process's name (pid 4194303 is above Linux's default pid_max
    // and far from any live process), without squeal's marker: the user's.
    let fake = dir.join(".squeal-4194303-0123456789abcdef.new");
    std::fs::create_dir(&fake).unwrap();
    std::fs::write(fake.join("thesis.tex"), "mine").unwrap();
    let o = squeal(
        dir,
        &["simulate", "belt", "--duration", "0.05", "--out", "r"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(std::fs::read(fake.join("thesis.tex")).unwrap(), b"mine");
    // The same name with squeal's marker of that dead process: stale, removed.
    let stale = dir.join(".squeal-4194303-fedcba9876543210.new");
    std::fs::create_dir(&stale).unwrap();
    std::fs::write(
        stale.join(".squeal-staging.json"),
        r#"{"written_by": "squeal", "pid": 4194303}"#,
    )
    .unwrap();
    std::fs::write(stale.join("series.csv"), "t\n").unwrap();
    let o = squeal(
        dir,
        &["simulate", "belt", "--duration", "0.05", "--out", "r2"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stale.exists(), "a marked stale staging folder is removed");
    assert!(fake.join("thesis.tex").is_file());
    // No staging marker ends up in an output folder.
    assert!(!dir.join("r/.squeal-staging.json").exists());
    let manifest = std::fs::read_to_string(dir.join("r/.squeal-manifest.json")).unwrap();
    assert!(!manifest.contains("staging"), "{manifest}");
}

#[test]
fn an_interrupt_removes_the_parent_folders_the_run_created() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    for sig in ["INT", "TERM"] {
        let child = Command::new(BIN)
            .current_dir(dir)
            .args(["simulate", "--duration", "5", "--out", "a/b/c"])
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // Wait for the staging folder, then interrupt.
        let start = Instant::now();
        while !dir.join("a/b").exists() && start.elapsed() < Duration::from_secs(30) {
            std::thread::sleep(Duration::from_millis(10));
        }
        std::thread::sleep(Duration::from_millis(200));
        let ok = Command::new("kill")
            .args([&format!("-{sig}"), &child.id().to_string()])
            .status()
            .unwrap()
            .success();
        assert!(ok);
        let o = child.wait_with_output().unwrap();
        let code = if sig == "INT" { 130 } else { 143 };
        assert_eq!(o.status.code(), Some(code), "{}", stderr(&o));
        assert!(
            !dir.join("a").exists(),
            "SIG{sig}: the parents squeal made are gone"
        );
    }
    // Parents that existed before stay.
    std::fs::create_dir(dir.join("mine")).unwrap();
    let o = squeal(dir, &["simulate", "--set", "N=-1", "--out", "mine/x/y"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(dir.join("mine").is_dir());
    assert!(!dir.join("mine/x").exists());
}

#[test]
fn a_failed_write_to_stderr_ends_with_the_runs_own_exit_code() {
    let d = tempfile::tempdir().unwrap();
    let full = || std::fs::File::create("/dev/full").unwrap();
    // Bad input: 2, not a panic's 101.
    for args in [
        vec!["simulate", "--set", "zzz=1"],
        vec!["stability", "--set", "N=-1"],
        vec!["no-such-command"],
        vec!["map", "--x", "N=1:2:2"],
    ] {
        let o = Command::new(BIN)
            .current_dir(d.path())
            .args(&args)
            .stderr(full())
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "{args:?}");
    }
    // A failure that is not bad input (stdout on a full disk): 1.
    let o = Command::new(BIN)
        .current_dir(d.path())
        .args(["stability"])
        .stdout(full())
        .stderr(full())
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    // A run that succeeds while its notes cannot be written: 0.
    let o = Command::new(BIN)
        .current_dir(d.path())
        .args(["simulate", "belt", "--duration", "0.05", "--out", "ok"])
        .stderr(full())
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0));
}

#[test]
fn error_lines_escape_control_characters_and_stay_short() {
    let d = tempfile::tempdir().unwrap();
    let o = squeal(d.path(), &["simulate", "--set", "a\nb\x1b[31mc=2"]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(err.matches('\n').count(), 1, "one line: {err:?}");
    assert!(!err.contains('\x1b'), "no raw ESC: {err:?}");
    assert!(err.contains("a\\nb\\u{1b}[31mc"), "{err}");
    // A 100 kB value is cut (today the line was 100 kB).
    let long = format!("N={}", "9".repeat(100_000));
    let o = squeal(d.path(), &["stability", "--set", &long]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2));
    assert!(err.len() < 3000, "{} bytes", err.len());
    assert!(err.contains("more characters)"), "{err}");
    // Paths with control characters too.
    let o = squeal(d.path(), &["plot", "no\rsuch\u{202e}run"]);
    let err = stderr(&o);
    assert!(!err.contains('\r') && !err.contains('\u{202e}'), "{err:?}");
}
