//! Issue 24, class 1, against the real binary: a generated SLURM script
//! runs only what the user asked. Every user-supplied string is quoted for
//! its context or refused; numeric options are bounded by what they mean.

use std::path::Path;
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_squeal");

fn squeal(dir: &Path, args: &[&str]) -> Output {
    Command::new(BIN)
        .current_dir(dir)
        .args(args)
        .output()
        .expect("squeal runs")
}

fn refused(o: &Output, needles: &[&str]) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "exit 2 expected: {err}");
    assert!(o.stdout.is_empty(), "nothing printed on refusal");
    for n in needles {
        assert!(err.contains(n), "{n:?} not in: {err}");
    }
}

const MAP: [&str; 7] = [
    "slurm",
    "map",
    "belt",
    "--x",
    "V=2:16:3",
    "--y",
    "c=0.05:1:2",
];

fn with<'a>(base: &[&'a str], more: &[&'a str]) -> Vec<&'a str> {
    let mut v = base.to_vec();
    v.extend_from_slice(more);
    v
}

/// Nothing but `#!`, comments, `#SBATCH` directives and the script's own
/// shell lines: the lines of a script squeal generated, by kind.
fn directives(script: &str) -> Vec<String> {
    script
        .lines()
        .filter(|l| l.starts_with("#SBATCH"))
        .map(str::to_string)
        .collect()
}

#[test]
fn a_newline_in_a_path_never_starts_a_directive_or_a_command() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    // In --jobs (today: a new #SBATCH line and a shell command).
    let evil = "jobs\n#SBATCH --uid=0\ntouch pwned\n";
    let o = squeal(dir, &with(&MAP, &["--tasks", "2", "--jobs", evil]));
    refused(&o, &["--jobs", "\\n", "#SBATCH line"]);
    // In the current folder (written as --chdir).
    let cwd = dir.join("work\n#SBATCH --uid=0");
    std::fs::create_dir(&cwd).unwrap();
    let o = squeal(&cwd, &with(&MAP, &["--tasks", "2"]));
    refused(&o, &["the current folder", "\\n"]);
    // In --out (the merge target) and in a scenario path: carried by the
    // shell lines, single-quoted, never by a directive.
    for bad in [
        vec!["--tasks", "2", "--jobs", "j\rk"],
        vec!["--tasks", "2", "--partition", "p\n#SBATCH --uid=0"],
        vec!["--tasks", "2", "--partition", "a b"],
        vec!["--tasks", "2", "--time", "10:00\n#SBATCH --uid=0"],
        vec!["--tasks", "2", "--time", "soon"],
    ] {
        let o = squeal(dir, &with(&MAP, &bad));
        assert_eq!(o.status.code(), Some(2), "{bad:?}");
    }
    assert!(std::fs::read_dir(dir).unwrap().all(|e| {
        let n = e.unwrap().file_name();
        n == "work\n#SBATCH --uid=0"
    }));
}

#[test]
fn hostile_strings_in_shell_lines_are_quoted_and_run_nothing() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    let jobs = "j 50% $(touch pwned) `touch pwned2`;touch pwned3";
    let o = squeal(
        dir,
        &with(
            &MAP,
            &[
                "--tasks",
                "2",
                "--jobs",
                jobs,
                "--out",
                "m $(touch pwned4)",
                "--set",
                "N=3000",
                "--time",
                "1-02:00:00",
                "--partition",
                "batch,debug",
            ],
        ),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let array = std::fs::read_to_string(dir.join(jobs).join("array.sh")).unwrap();
    let merge = std::fs::read_to_string(dir.join(jobs).join("merge.sh")).unwrap();
    // Exactly the directives asked for; `%` of the folder escaped for
    // SLURM's file-name patterns, `%a` kept.
    let want_out = format!(
        "#SBATCH --output='{}/j 50%% $(touch pwned) `touch pwned2`;touch pwned3/shard-%a.log'",
        dir.display()
    );
    assert_eq!(
        directives(&array),
        vec![
            "#SBATCH --job-name=squeal-map".to_string(),
            "#SBATCH --array=0-1".into(),
            want_out,
            format!("#SBATCH --chdir='{}'", dir.display()),
            "#SBATCH --partition=batch,debug".into(),
            "#SBATCH --time=1-02:00:00".into(),
        ]
    );
    assert_eq!(directives(&merge).len(), 5, "{merge}");
    // The scripts parse, and running them (task 0 and the merge, with
    // squeal itself) creates none of the files the strings name.
    for (script, env) in [("array.sh", "0"), ("merge.sh", "")] {
        let path = dir.join(jobs).join(script);
        let ok = Command::new("bash")
            .arg("-n")
            .arg(&path)
            .status()
            .unwrap()
            .success();
        assert!(ok, "{script} parses");
        let o = Command::new("bash")
            .arg(&path)
            .current_dir(dir)
            .env("SLURM_ARRAY_TASK_ID", env)
            .output()
            .unwrap();
        if script == "array.sh" {
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
            // Task 1 too, so that the merge has both shards.
            let o = Command::new("bash")
                .arg(&path)
                .current_dir(dir)
                .env("SLURM_ARRAY_TASK_ID", "1")
                .output()
                .unwrap();
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        } else {
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        }
    }
    for f in ["pwned", "pwned2", "pwned3", "pwned4"] {
        assert!(!dir.join(f).exists(), "{f} was created: a command ran");
    }
    assert!(dir.join("m $(touch pwned4)/map.csv").is_file());
}

#[test]
fn numeric_options_are_bounded_by_what_they_mean() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    // 3 × 2 = 6 points (today: an array of 10⁹ tasks).
    let o = squeal(dir, &with(&MAP, &["--tasks", "1000000000"]));
    refused(&o, &["--tasks 1000000000", "the 6 points of the map"]);
    let o = squeal(dir, &with(&MAP, &["--tasks", "7"]));
    refused(&o, &["--tasks 7", "6 points"]);
    let o = squeal(dir, &with(&MAP, &["--tasks", "6"]));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = squeal(dir, &["slurm", "reproduce", "--tasks", "41"]);
    refused(&o, &["--tasks 41", "40 sets"]);
    let o = squeal(
        dir,
        &with(
            &MAP,
            &["--tasks", "2", "--cpus-per-task", "100000", "--jobs", "c"],
        ),
    );
    refused(&o, &["--cpus-per-task 100000", "4096"]);
    let o = squeal(
        dir,
        &[
            "slurm", "sweep", "hoffmann", "--param", "mu=0:1:5", "--tasks", "6",
        ],
    );
    refused(&o, &["--tasks 6", "5 values"]);
}
