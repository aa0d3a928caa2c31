//! `squeal map … --shard K/N` and `squeal merge`: a merged map is the
//! unsharded one byte for byte; shards of another study, missing,
//! duplicated or truncated shards are refused (exit 2) with the reason.

use std::path::Path;
use std::process::{Command, Output};

fn squeal_raw(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_squeal"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("squeal runs")
}

fn squeal(dir: &Path, args: &[&str]) -> Output {
    let out = squeal_raw(dir, args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Exit code 2, one line naming `why`, and nothing written at `out`.
fn refused(dir: &Path, args: &[&str], why: &str) {
    let out = squeal_raw(dir, args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    assert!(err.contains(why), "{args:?}: expected {why:?} in {err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(!dir.join("merged").exists(), "nothing written");
}

const LINEAR: [&str; 5] = ["map", "--x", "V=0.5:20:5", "--y", "N=100:3000:4"];
const TRANSIENT: [&str; 9] = [
    "map",
    "belt",
    "--x",
    "V=2:16:4",
    "--y",
    "c=0.05:1:3",
    "--transient",
    "--duration",
    "1.5",
];

fn with<'a>(base: &[&'a str], more: &[&'a str]) -> Vec<&'a str> {
    base.iter().chain(more).copied().collect()
}

/// Shard `base` into `n` (into `DIR/s{n}-{k}`), merge into `DIR/m{n}`, and
/// compare every file with the unsharded run in `DIR/full`.
fn shards_merge_to_the_unsharded_map(base: &[&str], files: &[&str]) {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    squeal(dir, &with(base, &["--out", "full"]));
    for n in [1usize, 2, 3, 7] {
        let mut dirs = Vec::new();
        for k in 0..n {
            let out = format!("s{n}-{k}");
            let shard = format!("{k}/{n}");
            squeal(dir, &with(base, &["--shard", &shard, "--out", &out]));
            dirs.push(out);
        }
        let m = format!("m{n}");
        // Shards in any order.
        dirs.reverse();
        let mut args: Vec<&str> = vec!["merge"];
        args.extend(dirs.iter().map(String::as_str));
        args.extend(["--out", &m]);
        let out = squeal(dir, &args);
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(
            text.contains(&format!("points from {n} shards; 0 failed points")),
            "{text}"
        );
        for f in files {
            let a = std::fs::read(dir.join("full").join(f)).unwrap();
            let b = std::fs::read(dir.join(&m).join(f)).unwrap();
            assert!(a == b, "{f} differs after merging {n} shards");
        }
    }
}

#[test]
fn linear_shards_merge_byte_identical() {
    // 20 points: 20 / 3 and 20 / 7 leave uneven slices.
    shards_merge_to_the_unsharded_map(&LINEAR, &["map.csv", "map.png", "map.svg"]);
}

#[test]
fn transient_shards_merge_byte_identical() {
    // 12 points: slices of 4 / 4 / 4 and 2 / 2 / 2 / 2 / 2 / 1 / 1.
    shards_merge_to_the_unsharded_map(
        &TRANSIENT,
        &[
            "map.csv",
            "map.png",
            "map.svg",
            "transient.png",
            "transient.svg",
        ],
    );
}

fn three_shards(dir: &Path, base: &[&str], prefix: &str) {
    for k in 0..3 {
        let (shard, out) = (format!("{k}/3"), format!("{prefix}{k}"));
        squeal(dir, &with(base, &["--shard", &shard, "--out", &out]));
    }
}

#[test]
fn merge_refuses_missing_duplicated_and_foreign_shards() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    three_shards(dir, &LINEAR, "a");
    let m = ["--out", "merged"];
    // Shard 1 of 3 holds points 1, 4, 7, … 19.
    refused(
        dir,
        &with(&["merge", "a0", "a2"], &m),
        "missing shard 1/3 (points 1, 4, 7, 10, 13, 16, 19)",
    );
    refused(
        dir,
        &with(&["merge", "a0", "a1", "a1", "a2"], &m),
        "shard 1/3 given twice",
    );
    // Another scenario (a changed parameter) and another grid.
    squeal(
        dir,
        &with(
            &LINEAR,
            &["--set", "m_p=0.2", "--shard", "1/3", "--out", "b1"],
        ),
    );
    refused(
        dir,
        &with(&["merge", "a0", "b1", "a2"], &m),
        "different scenarios",
    );
    let other_grid = ["map", "--x", "V=0.5:20:5", "--y", "N=100:3100:4"];
    squeal(dir, &with(&other_grid, &["--shard", "1/3", "--out", "g1"]));
    refused(
        dir,
        &with(&["merge", "a0", "g1", "a2"], &m),
        "different grids",
    );
    squeal(dir, &with(&LINEAR, &["--shard", "1/2", "--out", "n1"]));
    refused(
        dir,
        &with(&["merge", "a0", "n1", "a2"], &m),
        "different numbers of shards",
    );
    // All good: it merges.
    squeal(dir, &with(&["merge", "a0", "a1", "a2"], &m));
}

#[test]
fn merge_refuses_truncated_and_half_written_shards() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    three_shards(dir, &TRANSIENT, "t");
    let m = ["--out", "merged"];
    let part = dir.join("t1/part.csv");
    let text = std::fs::read_to_string(&part).unwrap();
    std::fs::write(&part, &text[..text.len() - 20]).unwrap();
    refused(
        dir,
        &with(&["merge", "t0", "t1", "t2"], &m),
        "t1: part.csv is truncated or changed",
    );
    // A folder without its manifest (as a killed job could leave) is no shard.
    std::fs::remove_file(dir.join("t2/shard.json")).unwrap();
    refused(
        dir,
        &with(&["merge", "t0", "t2"], &m),
        "t2: not a complete shard",
    );
    // A truncated manifest.
    let man = dir.join("t0/shard.json");
    let text = std::fs::read_to_string(&man).unwrap();
    std::fs::write(&man, &text[..text.len() / 2]).unwrap();
    refused(
        dir,
        &with(&["merge", "t0"], &m),
        "t0: shard.json is damaged",
    );
}

#[test]
fn a_failed_shard_is_recomputed_alone() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    squeal(dir, &with(&TRANSIENT, &["--out", "full"]));
    three_shards(dir, &TRANSIENT, "t");
    // Shard 1 is damaged; recomputing just it (into the same
    // folder, which it replaces) repairs the study.
    std::fs::write(dir.join("t1/part.csv"), "index\n").unwrap();
    refused(
        dir,
        &["merge", "t0", "t1", "t2", "--out", "merged"],
        "truncated or changed",
    );
    squeal(dir, &with(&TRANSIENT, &["--shard", "1/3", "--out", "t1"]));
    squeal(dir, &["merge", "t0", "t1", "t2", "--out", "merged"]);
    let a = std::fs::read(dir.join("full/map.csv")).unwrap();
    let b = std::fs::read(dir.join("merged/map.csv")).unwrap();
    assert!(a == b);
}

#[test]
fn shard_flag_is_checked() {
    let d = tempfile::tempdir().unwrap();
    for bad in ["3/3", "1/0", "one/2"] {
        let out = squeal_raw(d.path(), &with(&LINEAR, &["--shard", bad, "--out", "s"]));
        assert_eq!(out.status.code(), Some(2));
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(&format!("--shard {bad}")), "{err}");
        assert!(!d.path().join("s").exists());
    }
}

#[test]
fn slurm_scripts_run_as_an_array_and_merge() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    squeal(dir, &with(&LINEAR, &["--out", "full"]));
    let args = with(
        &LINEAR,
        &[
            "--tasks",
            "3",
            "--partition",
            "short",
            "--time",
            "0:10:00",
            "--cpus-per-task",
            "2",
            "--out",
            "merged",
        ],
    );
    let mut slurm = vec!["slurm"];
    slurm.extend(&args);
    let out = squeal(dir, &slurm);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("sbatch --array=K"), "{text}");
    let array = std::fs::read_to_string(dir.join("merged-slurm/array.sh")).unwrap();
    for line in [
        "#SBATCH --array=0-2",
        "#SBATCH --partition=short",
        "#SBATCH --time=0:10:00",
        "#SBATCH --cpus-per-task=2",
        "export RAYON_NUM_THREADS=\"${SLURM_CPUS_PER_TASK:-1}\"",
    ] {
        assert!(array.lines().any(|l| l == line), "{line} not in {array}");
    }
    assert!(array.contains("--shard \"$K/3\""), "{array}");
    // Run the scripts the way SLURM would: every task, then the merge.
    let bash = |script: &str, task: Option<usize>| {
        let mut c = Command::new("bash");
        c.current_dir(dir)
            .arg(dir.join("merged-slurm").join(script));
        if let Some(k) = task {
            c.env("SLURM_ARRAY_TASK_ID", k.to_string());
        }
        let o = c.output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    for k in 0..3 {
        bash("array.sh", Some(k));
    }
    bash("merge.sh", None);
    for f in ["map.csv", "map.png", "map.svg"] {
        let a = std::fs::read(dir.join("full").join(f)).unwrap();
        let b = std::fs::read(dir.join("merged").join(f)).unwrap();
        assert!(a == b, "{f}");
    }
}

#[test]
fn slurm_refuses_bad_job_settings() {
    let d = tempfile::tempdir().unwrap();
    for (more, why) in [
        (&["--tasks", "0"][..], "--tasks 0"),
        (&["--tasks", "2", "--shard", "0/2"][..], "--shard"),
        (&["--tasks", "2", "--time", "1 day"][..], "--time"),
        (
            &["--tasks", "2", "--cpus-per-task", "0"][..],
            "--cpus-per-task 0",
        ),
    ] {
        let mut args = vec!["slurm"];
        args.extend(&LINEAR);
        args.extend(more);
        args.extend(["--out", "merged"]);
        refused(d.path(), &args, why);
        assert!(!d.path().join("merged-slurm").exists());
    }
}

#[test]
fn a_shard_with_json_prints_json_only() {
    let d = tempfile::tempdir().unwrap();
    let out = squeal(
        d.path(),
        &with(&LINEAR, &["--shard", "2/7", "--out", "s", "--json"]),
    );
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON only");
    // Points 2, 9, 16 of 20.
    assert_eq!(
        (j["shard"].as_u64(), j["points"].as_u64()),
        (Some(2), Some(3))
    );
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.path().join("s/shard.json")).unwrap())
            .unwrap();
    assert_eq!((m["k"].as_u64(), m["n"].as_u64()), (Some(2), Some(7)));
}

/// A transient map whose stiffest row really fails: at c = 1e10 kg/s the
/// belt's overdamped mode has |λ| = c/m = 1e10 1/s, and 0.05 s would need
/// at least 0.05·1e10/6.5 ≈ 7.7e7 explicit steps (limit 1e7), so those
/// runs are refused as too stiff; the other rows run.
const FAILING: [&str; 10] = [
    "map",
    "belt",
    "--x",
    "V=2:16:3",
    "--y",
    "c=1:1e10:3",
    "--log-y",
    "--transient",
    "--duration",
    "0.05",
];

#[test]
fn failed_points_are_merged_as_failed_and_reported() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    // The failure is real: the same run alone is refused as too stiff.
    let one = squeal_raw(
        dir,
        &[
            "simulate",
            "belt",
            "--set",
            "c=1e10",
            "--set",
            "V=2",
            "--duration",
            "0.05",
            "--out",
            "one",
        ],
    );
    let err = String::from_utf8_lossy(&one.stderr);
    assert_eq!(one.status.code(), Some(1), "{err}");
    assert!(
        err.contains("too stiff") && err.contains("set by c = 1e10"),
        "{err}"
    );
    squeal(dir, &with(&FAILING, &["--out", "full"]));
    let csv = std::fs::read_to_string(dir.join("full/map.csv")).unwrap();
    // Rows y-major: points 6, 7, 8 are c = 1e10, and only they failed.
    for (i, line) in csv.lines().skip(1).enumerate() {
        let f: Vec<&str> = line.split(',').collect();
        assert_eq!(f[4] == "failed", i >= 6, "{line}");
        if i >= 6 {
            assert_eq!(&f[5..], ["nan", "nan", "nan", "n/a", "nan"], "{line}");
        }
    }
    for n in [2usize, 3] {
        let mut args: Vec<String> = vec!["merge".into()];
        for k in 0..n {
            let out = format!("f{n}-{k}");
            squeal(
                dir,
                &with(&FAILING, &["--shard", &format!("{k}/{n}"), "--out", &out]),
            );
            args.push(out);
        }
        let m = format!("m{n}");
        args.extend(["--out".into(), m.clone()]);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = squeal(dir, &args);
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(
            text.contains(&format!(
                "merged 9 points from {n} shards; 3 failed points (recorded as failed in map.csv): 6, 7, 8"
            )),
            "{text}"
        );
        for f in [
            "map.csv",
            "map.png",
            "map.svg",
            "transient.png",
            "transient.svg",
        ] {
            let a = std::fs::read(dir.join("full").join(f)).unwrap();
            let b = std::fs::read(dir.join(&m).join(f)).unwrap();
            assert!(a == b, "{f} differs after merging {n} shards");
        }
    }
}

/// `reproduce` at a fiftieth of the shipped durations.
const REPRODUCE: [&str; 3] = ["reproduce", "--duration-scale", "0.02"];

/// Every file under `root`, relative, sorted.
fn files_under(root: &Path) -> Vec<std::path::PathBuf> {
    let mut out = Vec::new();
    let mut todo = vec![root.to_path_buf()];
    while let Some(d) = todo.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                todo.push(p);
            } else {
                out.push(p.strip_prefix(root).unwrap().to_path_buf());
            }
        }
    }
    out.sort();
    out
}

/// The same files, byte for byte, in both folders.
fn same_tree(a: &Path, b: &Path) {
    let (fa, fb) = (files_under(a), files_under(b));
    assert_eq!(fa, fb, "different files");
    for f in fa {
        assert!(
            std::fs::read(a.join(&f)).unwrap() == std::fs::read(b.join(&f)).unwrap(),
            "{} differs",
            f.display()
        );
    }
}

fn reproduce_shards(dir: &Path, base: &[&str], n: usize, prefix: &str) -> Vec<String> {
    (0..n)
        .map(|k| {
            let out = format!("{prefix}{k}");
            squeal(
                dir,
                &with(base, &["--shard", &format!("{k}/{n}"), "--out", &out]),
            );
            out
        })
        .collect()
}

#[test]
fn reproduce_shards_merge_byte_identical() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    let base = with(&REPRODUCE, &["--no-figures"]);
    squeal(dir, &with(&base, &["--out", "full"]));
    // What squeal owns (its manifest) and the report; same_tree compares all.
    let files: Vec<std::path::PathBuf> = [
        ".squeal-manifest.json",
        "conclusions.json",
        "map.png",
        "map.svg",
        "report.html",
        "report.md",
        "table.csv",
    ]
    .iter()
    .map(std::path::PathBuf::from)
    .collect();
    assert_eq!(files_under(&dir.join("full")), files);
    // 40 sets in 3 shards: 14 / 13 / 13.
    for n in [1usize, 3] {
        let mut dirs = reproduce_shards(dir, &base, n, &format!("r{n}-"));
        dirs.reverse();
        let m = format!("m{n}");
        let mut args: Vec<&str> = vec!["merge"];
        args.extend(dirs.iter().map(String::as_str));
        args.extend(["--out", &m]);
        let out = squeal(dir, &args);
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(
            text.contains(&format!("merged 40 sets from {n} shards: ")),
            "{text}"
        );
        same_tree(&dir.join("full"), &dir.join(&m));
    }
    let man: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("r3-1/shard.json")).unwrap())
            .unwrap();
    assert_eq!(man["study"]["command"], "reproduce");
    assert_eq!(man["points"], 13, "sets 2, 5, … 38");
}

#[test]
fn reproduce_shards_with_figures_merge_byte_identical() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    squeal(dir, &with(&REPRODUCE, &["--out", "full"]));
    assert!(dir.join("full/figures/set40").is_dir());
    let dirs = reproduce_shards(dir, &REPRODUCE, 2, "r");
    squeal(dir, &["merge", &dirs[0], &dirs[1], "--out", "merged"]);
    same_tree(&dir.join("full"), &dir.join("merged"));
    std::fs::remove_dir_all(dir.join("merged")).unwrap();
    // A picture cut short is found.
    let shard = dir.join("r1/figures/set02");
    let pic = std::fs::read_dir(&shard)
        .unwrap()
        .next()
        .unwrap()
        .unwrap()
        .path();
    let bytes = std::fs::read(&pic).unwrap();
    std::fs::write(&pic, &bytes[..bytes.len() / 2]).unwrap();
    let name = pic.file_name().unwrap().to_string_lossy().to_string();
    refused(
        dir,
        &["merge", "r0", "r1", "--out", "merged"],
        &format!("r1: figures/set02/{name} is truncated or changed"),
    );
}

#[test]
fn merge_refuses_bad_reproduce_shards() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    let base = with(&REPRODUCE, &["--no-figures"]);
    reproduce_shards(dir, &base, 3, "a");
    let m = ["--out", "merged"];
    refused(
        dir,
        &with(&["merge", "a0", "a2"], &m),
        "missing shard 1/3 (sets 2, 5, 8, 11, 14, 17, 20, 23, 26, 29, 32, 35 … (13 in all))",
    );
    refused(
        dir,
        &with(&["merge", "a0", "a1", "a2", "a0"], &m),
        "shard 0/3 given twice",
    );
    // Another duration scale, with figures, a map's shard.
    squeal(
        dir,
        &[
            "reproduce",
            "--duration-scale",
            "0.03",
            "--no-figures",
            "--shard",
            "1/3",
            "--out",
            "b1",
        ],
    );
    refused(
        dir,
        &with(&["merge", "a0", "b1", "a2"], &m),
        "different --duration-scale",
    );
    squeal(dir, &with(&REPRODUCE, &["--shard", "1/3", "--out", "c1"]));
    refused(
        dir,
        &with(&["merge", "a0", "c1", "a2"], &m),
        "one draws figures, the other has --no-figures",
    );
    squeal(dir, &with(&LINEAR, &["--shard", "1/3", "--out", "g1"]));
    refused(
        dir,
        &with(&["merge", "a0", "g1", "a2"], &m),
        "different commands (\"reproduce\" and \"map\")",
    );
    // Truncated results.
    let part = dir.join("a1/part.json");
    let text = std::fs::read_to_string(&part).unwrap();
    std::fs::write(&part, &text[..text.len() - 30]).unwrap();
    refused(
        dir,
        &with(&["merge", "a0", "a1", "a2"], &m),
        "a1: part.json is truncated or changed",
    );
    // Recomputed alone, the shard repairs the study.
    squeal(dir, &with(&base, &["--shard", "1/3", "--out", "a1"]));
    squeal(dir, &with(&["merge", "a0", "a1", "a2"], &m));
}

#[test]
fn slurm_reproduce_scripts_run_as_an_array_and_merge() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    let base = with(&REPRODUCE, &["--no-figures"]);
    squeal(dir, &with(&base, &["--out", "full"]));
    let mut args = vec!["slurm"];
    args.extend(&base);
    args.extend(["--tasks", "2", "--out", "merged"]);
    squeal(dir, &args);
    let array = std::fs::read_to_string(dir.join("merged-slurm/array.sh")).unwrap();
    assert!(array.lines().any(|l| l == "#SBATCH --array=0-1"), "{array}");
    assert!(
        array.contains("reproduce --duration-scale 0.02 --no-figures --shard \"$K/2\""),
        "{array}"
    );
    let bash = |script: &str, task: Option<usize>| {
        let mut c = Command::new("bash");
        c.current_dir(dir)
            .arg(dir.join("merged-slurm").join(script));
        if let Some(k) = task {
            c.env("SLURM_ARRAY_TASK_ID", k.to_string());
        }
        let o = c.output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    bash("array.sh", Some(0));
    bash("array.sh", Some(1));
    bash("merge.sh", None);
    same_tree(&dir.join("full"), &dir.join("merged"));
}

const SWEEP_HOFFMANN: [&str; 8] = [
    "sweep",
    "hoffmann",
    "--param",
    "mu=0.05:0.5:46",
    "--set",
    "c1=0",
    "--set",
    "c2=0",
];
const SWEEP_DISC_PAD: [&str; 4] = ["sweep", "disc-pad", "--param", "V=0.5:20:40"];

/// The `--json` document without its `out`.
fn json_without_out(out: &Output) -> serde_json::Value {
    let mut j: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON only");
    j.as_object_mut().unwrap().remove("out");
    j
}

#[test]
fn sweep_shards_merge_byte_identical() {
    for base in [&SWEEP_HOFFMANN[..], &SWEEP_DISC_PAD[..]] {
        let d = tempfile::tempdir().unwrap();
        let dir = d.path();
        let full = json_without_out(&squeal(dir, &with(base, &["--out", "full", "--json"])));
        assert!(
            !full["onsets"].as_array().unwrap().is_empty(),
            "{base:?}: the sweep should cross a change of stability: {full}"
        );
        // 46 values in 7 slices of 6 or 7; 40 in 3 of 13 or 14.
        for n in [1usize, 2, 3, 7] {
            let mut args: Vec<String> = vec!["merge".into()];
            for k in (0..n).rev() {
                let out = format!("s{n}-{k}");
                squeal(
                    dir,
                    &with(base, &["--shard", &format!("{k}/{n}"), "--out", &out]),
                );
                args.push(out);
            }
            let m = format!("m{n}");
            args.extend(["--out".into(), m.clone(), "--json".into()]);
            let args: Vec<&str> = args.iter().map(String::as_str).collect();
            let merged = json_without_out(&squeal(dir, &args));
            assert_eq!(merged, full, "{base:?}: --json after merging {n} shards");
            for f in ["sweep.csv", "sweep.png", "sweep.svg"] {
                let a = std::fs::read(dir.join("full").join(f)).unwrap();
                let b = std::fs::read(dir.join(&m).join(f)).unwrap();
                assert!(a == b, "{base:?}: {f} differs after merging {n} shards");
            }
        }
    }
}

#[test]
fn merge_refuses_bad_sweep_shards() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    for k in 0..3 {
        squeal(
            dir,
            &with(
                &SWEEP_HOFFMANN,
                &["--shard", &format!("{k}/3"), "--out", &format!("a{k}")],
            ),
        );
    }
    let m = ["--out", "merged"];
    // 46 values: slices 0–14, 15–29, 30–45.
    refused(
        dir,
        &with(&["merge", "a0", "a2"], &m),
        "missing shard 1/3 (values 15, 16, 17, 18, 19, 20, 21, 22, 23, 24, 25, 26 … (15 in all))",
    );
    refused(
        dir,
        &with(&["merge", "a0", "a1", "a1", "a2"], &m),
        "shard 1/3 given twice",
    );
    let mut other = SWEEP_HOFFMANN;
    other[3] = "mu=0.05:0.6:46";
    squeal(dir, &with(&other, &["--shard", "1/3", "--out", "b1"]));
    refused(
        dir,
        &with(&["merge", "a0", "b1", "a2"], &m),
        "different --param",
    );
    squeal(
        dir,
        &with(
            &SWEEP_HOFFMANN,
            &["--set", "c1=0.1", "--shard", "1/3", "--out", "c1"],
        ),
    );
    refused(
        dir,
        &with(&["merge", "a0", "c1", "a2"], &m),
        "different scenarios",
    );
    let part = dir.join("a1/part.json");
    let text = std::fs::read_to_string(&part).unwrap();
    std::fs::write(&part, &text[..text.len() - 10]).unwrap();
    refused(
        dir,
        &with(&["merge", "a0", "a1", "a2"], &m),
        "a1: part.json is truncated or changed",
    );
    refused(
        dir,
        &with(&SWEEP_HOFFMANN, &["--shard", "0/47", "--out", "merged"]),
        "--shard 0/47: more shards than the 46 values",
    );
}

#[test]
fn slurm_sweep_scripts_run_as_an_array_and_merge() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    squeal(dir, &with(&SWEEP_HOFFMANN, &["--out", "full"]));
    let mut args = vec!["slurm"];
    args.extend(&SWEEP_HOFFMANN);
    args.extend(["--tasks", "3", "--out", "merged"]);
    squeal(dir, &args);
    let array = std::fs::read_to_string(dir.join("merged-slurm/array.sh")).unwrap();
    assert!(
        array.contains(
            "sweep hoffmann --set c1=0 --set c2=0 --param mu=0.05:0.5:46 --shard \"$K/3\""
        ),
        "{array}"
    );
    for k in 0..3 {
        let o = Command::new("bash")
            .current_dir(dir)
            .arg(dir.join("merged-slurm/array.sh"))
            .env("SLURM_ARRAY_TASK_ID", k.to_string())
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let o = Command::new("bash")
        .current_dir(dir)
        .arg(dir.join("merged-slurm/merge.sh"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in ["sweep.csv", "sweep.png", "sweep.svg"] {
        let a = std::fs::read(dir.join("full").join(f)).unwrap();
        let b = std::fs::read(dir.join("merged").join(f)).unwrap();
        assert!(a == b, "{f}");
    }
    let mut args = vec!["slurm"];
    args.extend(&SWEEP_HOFFMANN);
    args.extend(["--tasks", "47", "--out", "merged2"]);
    let out = squeal_raw(dir, &args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("--tasks 47: more tasks than the 46 values"),
        "{err}"
    );
    assert!(!dir.join("merged2-slurm").exists());
}
