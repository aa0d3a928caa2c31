//! Lumped scenario files end to end: the shipped files equal the built-ins,
//! Matrix Market matrices read from files, every command on a lumped model,
//! and bad files refused (exit 2) naming the element and key.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn squeal(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_squeal"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("squeal runs")
}

fn scenarios() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/lumped")
}

fn ok(out: &Output) -> String {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn json(out: &Output) -> serde_json::Value {
    serde_json::from_str(&ok(out)).unwrap()
}

#[test]
fn shipped_lumped_files_equal_the_built_ins() {
    let d = tempfile::tempdir().unwrap();
    for (file, builtin) in [("disc-pad.toml", "disc-pad"), ("hoffmann.toml", "hoffmann")] {
        let f = scenarios().join(file);
        let a = json(&squeal(
            d.path(),
            &["stability", f.to_str().unwrap(), "--json"],
        ));
        let b = json(&squeal(d.path(), &["stability", builtin, "--json"]));
        let (ea, eb) = (
            a["eigenvalues"].as_array().unwrap(),
            b["eigenvalues"].as_array().unwrap(),
        );
        assert_eq!(ea.len(), eb.len());
        for (x, y) in ea.iter().zip(eb) {
            let (xr, xi) = (x["re"].as_f64().unwrap(), x["im"].as_f64().unwrap());
            let (yr, yi) = (y["re"].as_f64().unwrap(), y["im"].as_f64().unwrap());
            let mag = yr.hypot(yi);
            assert!(
                (xr - yr).abs() <= 1e-10 * mag && (xi - yi).abs() <= 1e-10 * mag,
                "{file}: {x} vs {y}"
            );
        }
    }
    // Hoffmann's critical friction coefficient (the contact's Coulomb mu_k; mu_s above it).
    let f = scenarios().join("hoffmann.toml");
    let a = json(&squeal(
        d.path(),
        &[
            "critical",
            f.to_str().unwrap(),
            "--set",
            "belt.mu_s=2",
            "--param",
            "belt.mu_k=0.01:1",
            "--json",
        ],
    ));
    let b = json(&squeal(
        d.path(),
        &["critical", "hoffmann", "--param", "mu=0.01:1", "--json"],
    ));
    let (x, y) = (a["value"].as_f64().unwrap(), b["value"].as_f64().unwrap());
    assert!((x - y).abs() <= 1e-9 * y, "critical μ {x} vs {y}");
    // The belt: the same events as the built-in belt-coulomb.
    let f = scenarios().join("belt.toml");
    ok(&squeal(
        d.path(),
        &["simulate", f.to_str().unwrap(), "--out", "lb"],
    ));
    ok(&squeal(
        d.path(),
        &["simulate", "belt-coulomb", "--out", "bb"],
    ));
    let ev = |dir: &str| -> Vec<(f64, String)> {
        std::fs::read_to_string(d.path().join(dir).join("events.csv"))
            .unwrap()
            .lines()
            .skip(1)
            .map(|l| {
                let c: Vec<&str> = l.split(',').collect();
                (c[0].parse().unwrap(), c[1].to_string())
            })
            .collect()
    };
    let (la, lb) = (ev("lb"), ev("bb"));
    assert!(
        la.len() >= 10 && la.len() == lb.len(),
        "{} vs {}",
        la.len(),
        lb.len()
    );
    for (x, y) in la.iter().zip(&lb) {
        assert_eq!(x.1, y.1);
        assert!((x.0 - y.0).abs() <= 1e-8, "{x:?} vs {y:?}");
    }
}

#[test]
fn every_command_runs_on_a_lumped_model() {
    let d = tempfile::tempdir().unwrap();
    ok(&squeal(
        d.path(),
        &[
            "simulate",
            "two-pad-brake-asymmetric",
            "--duration",
            "0.005",
            "--out",
            "tp",
        ],
    ));
    let dir = d.path().join("tp");
    let series = std::fs::read_to_string(dir.join("series.csv")).unwrap();
    let header = series.lines().next().unwrap();
    assert_eq!(
        header,
        "t,x_d,y_d,x_p1,y_p1,x_p2,y_p2,vx_d,vy_d,vx_p1,vy_p1,vx_p2,vy_p2,\
         pad1.F_n,pad1.F_t,pad1.v_rel,pad1.mode,pad2.F_n,pad2.F_t,pad2.v_rel,pad2.mode"
    );
    let events = std::fs::read_to_string(dir.join("events.csv")).unwrap();
    assert_eq!(events.lines().next(), Some("t,kind,contact"));
    assert!(
        events
            .lines()
            .skip(1)
            .all(|l| l.ends_with(",pad1") || l.ends_with(",pad2")),
        "{events}"
    );
    let st = json(&squeal(
        d.path(),
        &["stability", "two-pad-brake", "--json", "--set", "pad2.V=2"],
    ));
    assert_eq!(st["eigenvalues"].as_array().unwrap().len(), 12);
    let c = json(&squeal(
        d.path(),
        &[
            "critical",
            "two-pad-brake",
            "--set",
            "pad2.f1=0",
            "--param",
            "pad1.f1=0:0.06",
            "--json",
        ],
    ));
    assert!(c["value"].as_f64().is_some(), "{c}");
    ok(&squeal(
        d.path(),
        &[
            "map",
            "two-pad-brake",
            "--x",
            "pad1.V=0.5:20:4",
            "--y",
            "brake_1.value=-3000:-100:3",
            "--out",
            "m",
        ],
    ));
    let shown = ok(&squeal(d.path(), &["scenario", "show", "two-pad-brake"]));
    assert!(
        shown.contains("[[contact]]") && shown.contains("name = \"pad2\""),
        "{shown}"
    );
}

/// Hoffmann's model embedded in a larger system read from Matrix Market
/// files: `M`, `K`, `C` hold the Hoffmann block (without the contact, which
/// stays an element) and 298 decoupled, damped oscillators; the critical
/// friction coefficient is the built-in model's.
#[test]
fn matrix_market_hoffmann_in_a_300_dof_system_has_the_same_critical_mu() {
    let d = tempfile::tempdir().unwrap();
    let n = 300;
    let (k11, k12, k22, k3, c1, c2, n0) = (1.0e4, 2.0e3, 1.2e4, 1.0e4, 0.5, 0.5, 100.0);
    let (mut m, mut k, mut c) = (String::new(), String::new(), String::new());
    let mut mk = Vec::new();
    let mut kk = vec![(1, 1, k11), (2, 1, k12), (2, 2, k22 - k3)];
    let mut ck = vec![(1, 1, c1), (2, 2, c2)];
    mk.push((1, 1, 1.0));
    mk.push((2, 2, 1.0));
    for i in 3..=n {
        let f = i as f64;
        mk.push((i, i, 0.5 + 0.01 * f));
        kk.push((i, i, 1.0e4 * (1.0 + 0.1 * f)));
        ck.push((i, i, 1.0 + 0.01 * f));
    }
    for (text, entries) in [(&mut m, &mk), (&mut k, &kk), (&mut c, &ck)] {
        *text = format!(
            "%%MatrixMarket matrix coordinate real symmetric\n% squeal test\n{n} {n} {}\n",
            entries.len()
        );
        for (r, col, v) in entries.iter() {
            text.push_str(&format!("{r} {col} {v:e}\n"));
        }
    }
    std::fs::write(d.path().join("M.mtx"), m).unwrap();
    std::fs::write(d.path().join("K.mtx"), k).unwrap();
    std::fs::write(d.path().join("C.mtx"), c).unwrap();
    let y0 = n0 / k3;
    let toml = format!(
        r#"name = "big"
model = "lumped"

[matrices]
M = "M.mtx"
K = "K.mtx"
C = "C.mtx"

[[force]]
name = "fx"
on = {{ q1 = 1.0 }}
value = {}

[[force]]
name = "fy"
on = {{ q2 = 1.0 }}
value = {}

[[contact]]
name = "belt"
normal = {{ q2 = 1.0 }}
k = {k3}
c = 0.0
tangent = {{ q1 = -1.0 }}
V = 1.0
friction = "coulomb"
mu_s = 2.0
mu_k = 0.3
"#,
        k12 * y0,
        k22 * y0
    );
    std::fs::write(d.path().join("big.toml"), toml).unwrap();
    let a = json(&squeal(
        d.path(),
        &[
            "critical",
            "big.toml",
            "--param",
            "belt.mu_k=0.01:1",
            "--grid",
            "12",
            "--json",
        ],
    ));
    let b = json(&squeal(
        d.path(),
        &[
            "critical",
            "hoffmann",
            "--param",
            "mu=0.01:1",
            "--grid",
            "12",
            "--json",
        ],
    ));
    let (x, y) = (a["value"].as_f64().unwrap(), b["value"].as_f64().unwrap());
    assert!((x - y).abs() <= 1e-9 * y, "critical μ {x} vs {y}");
    // The projected analysis on the 20 lowest undamped modes: K_s is block
    // diagonal (Hoffmann's block, then the decoupled dofs) and the block's
    // two modes are among the 20 lowest, so the basis holds the block
    // exactly and the critical μ is the same.
    let projected = ["--set", "modal.dense_max_dofs=0", "--set", "modal.modes=20"];
    let mut args = vec![
        "critical",
        "big.toml",
        "--param",
        "belt.mu_k=0.01:1",
        "--grid",
        "12",
        "--json",
    ];
    args.extend(projected);
    let p = json(&squeal(d.path(), &args));
    let z = p["value"].as_f64().unwrap();
    assert!((z - y).abs() <= 1e-9 * y, "projected critical μ {z} vs {y}");
    assert_eq!(p["modal"]["method"], "projected");
    assert_eq!(p["modal"]["modes"], 20);
    assert_eq!(a["modal"]["method"], "dense");
    let mut args = vec!["stability", "big.toml", "--json"];
    args.extend(projected);
    let s = json(&squeal(d.path(), &args));
    assert_eq!(s["modal"]["method"], "projected");
    assert_eq!(s["modal"]["modes"], 20);
    assert_eq!(s["modal"]["dofs"], n);
    assert_eq!(s["eigenvalues"].as_array().unwrap().len(), 40);
    let dense = json(&squeal(d.path(), &["stability", "big.toml", "--json"]));
    assert_eq!(dense["modal"]["method"], "dense");
    assert_eq!(dense["eigenvalues"].as_array().unwrap().len(), 2 * n);
    let human = ok(&squeal(
        d.path(),
        &[
            "stability",
            "big.toml",
            "--set",
            "modal.dense_max_dofs=0",
            "--set",
            "modal.modes=20",
        ],
    ));
    assert!(
        human.contains("projected onto the 20 lowest undamped modes of 300 dofs"),
        "{human}"
    );
    // The same options from the file's [modal] table.
    let text = std::fs::read_to_string(d.path().join("big.toml")).unwrap();
    std::fs::write(
        d.path().join("big-modal.toml"),
        format!("{text}\n[modal]\ndense_max_dofs = 0\nmodes = 20\n"),
    )
    .unwrap();
    let f = json(&squeal(
        d.path(),
        &["stability", "big-modal.toml", "--json"],
    ));
    assert_eq!(f["modal"], s["modal"]);
    assert_eq!(f["eigenvalues"], s["eigenvalues"]);
    std::fs::write(
        d.path().join("bad-modal.toml"),
        format!("{text}\n[modal]\nshift = 3\n"),
    )
    .unwrap();
    let out = squeal(d.path(), &["stability", "bad-modal.toml"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("modal.shift"));
    let out = squeal(
        d.path(),
        &["stability", "big.toml", "--set", "modal.modes=2.5"],
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("modal.modes"));
    // Cycles are refused for a model this size, with the limit stated
    // (simulation runs it: `a_150_dof_file_simulates_in_a_transient_size…`).
    let out = squeal(d.path(), &["cycle", "big.toml"]);
    assert_eq!(out.status.code(), Some(2));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("300 dofs") && e.contains("up to 128"), "{e}");
}

/// `series.csv` of the run in `dir`: its header and rows.
fn read_series(dir: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(dir.join("series.csv")).unwrap();
    let mut lines = text.lines();
    let head: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    (head, rows)
}

/// Index of column `name` in header `h`.
fn col(h: &[String], name: &str) -> usize {
    h.iter().position(|c| c == name).unwrap()
}

/// RMS of column `name` over rows `r`.
fn rms(h: &[String], r: &[Vec<f64>], name: &str) -> f64 {
    let c = col(h, name);
    (r.iter().map(|row| row[c] * row[c]).sum::<f64>() / r.len() as f64).sqrt()
}

/// `simulate` of `file` (in `dir`, into `out`) and of the 4-dof disc–pad
/// file (into `b4`) for `duration` seconds, CSV series, no plots: the big
/// run's human summary.
fn simulate_beside_disc_pad(dir: &Path, file: &str, out: &str, duration: &str) -> String {
    let args = ["--duration", duration, "--no-plots", "--format", "csv"];
    let mut a = vec!["simulate", file, "--out", out];
    a.extend(args);
    let human = ok(&squeal(dir, &a));
    let small = scenarios().join("disc-pad.toml");
    let mut a = vec!["simulate", small.to_str().unwrap(), "--out", "b4"];
    a.extend(args);
    ok(&squeal(dir, &a));
    human
}

/// The disc–pad scenario file with a separate chain of `links` masses
/// (`c1`…, 0.5 kg on 1e6 N/m springs), `c1` starting displaced by 1 mm; and
/// the chain's dof names.
fn disc_pad_with_chain(links: usize) -> (String, Vec<String>) {
    let base = std::fs::read_to_string(scenarios().join("disc-pad.toml")).unwrap();
    let chain: Vec<String> = (1..=links).map(|i| format!("c{i}")).collect();
    let mut text = base.replace(
        r#"dofs = ["x_d", "x_p", "y_d", "y_p"]"#,
        &format!(
            "dofs = [\"x_d\", \"x_p\", \"y_d\", \"y_p\", {}]",
            chain
                .iter()
                .map(|c| format!("\"{c}\""))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    );
    text = text.replacen(
        "y_p = 0.1\n",
        &format!(
            "y_p = 0.1\n{}",
            chain
                .iter()
                .map(|c| format!("{c} = 0.5\n"))
                .collect::<String>()
        ),
        1,
    );
    for (i, c) in chain.iter().enumerate() {
        let on = if i == 0 {
            format!("{{ {c} = 1.0 }}")
        } else {
            format!("{{ {c} = 1.0, {} = -1.0 }}", chain[i - 1])
        };
        text.push_str(&format!(
            "\n[[spring]]\nname = \"chain{}\"\non = {on}\nk = 1.0e6\nc = 0.5\n",
            i + 1
        ));
    }
    text.push_str("\n[offsets]\nc10 = 1e-3\n"); // c1 starts displaced (offset keys are <state>0)
    (text, chain)
}

/// A 20-dof lumped file (the disc–pad plus a separate chain of 16 masses,
/// ringing from a displacement): `simulate` runs it (padded to 24 dofs
/// inside, see `squeal_core::model::lumped::padding`) and writes exactly the
/// file's dofs; its disc–pad moves as the 4-dof file's does (RMS to 1e-6:
/// the steps differ because the error norm also weighs the chain); `map
/// --transient` runs it.
#[test]
fn a_20_dof_file_simulates_and_maps() {
    let d = tempfile::tempdir().unwrap();
    let (text, chain) = disc_pad_with_chain(16);
    std::fs::write(d.path().join("big20.toml"), &text).unwrap();
    simulate_beside_disc_pad(d.path(), "big20.toml", "b20", "0.1");
    let (h20, r20) = read_series(&d.path().join("b20"));
    let (h4, r4) = read_series(&d.path().join("b4"));
    let mut want = vec!["t".to_string()];
    for q in ["x_d", "x_p", "y_d", "y_p"]
        .iter()
        .map(|s| s.to_string())
        .chain(chain.clone())
    {
        want.push(q);
    }
    for q in ["x_d", "x_p", "y_d", "y_p"]
        .iter()
        .map(|s| s.to_string())
        .chain(chain.clone())
    {
        want.push(format!("v{q}"));
    }
    for c in ["F_n", "F_t", "v_rel", "mode"] {
        want.push(format!("pad.{c}"));
    }
    assert_eq!(h20, want, "series.csv columns");
    assert_eq!(r20.len(), r4.len());
    for name in ["vx_d", "vx_p", "vy_d", "vy_p"] {
        let (x, y) = (rms(&h4, &r4, name), rms(&h20, &r20, name));
        assert!((x - y).abs() <= 1e-6 * x, "{name}: RMS {x:e} vs {y:e}");
    }
    let c16 = col(&h20, "c16");
    assert!(
        r20.iter().any(|row| row[c16].abs() > 1e-6),
        "the chain never rang"
    );
    let out = squeal(
        d.path(),
        &[
            "map",
            "big20.toml",
            "--x",
            "pad.V=0.5:2:2",
            "--y",
            "brake.value=-800:-200:2",
            "--transient",
            "--duration",
            "0.02",
            "--out",
            "m20",
        ],
    );
    ok(&out);
    let map = std::fs::read_to_string(d.path().join("m20/map.csv")).unwrap();
    assert_eq!(map.lines().count(), 5, "{map}");
    assert!(!map.contains("failed"), "{map}");
}

/// A 150-dof lumped file (the disc–pad plus a chain of 146 masses) is above
/// the limit-cycle sizes (128 dofs) and runs in a transient-only padded size
/// (192 dofs, `padding::TRANSIENT_PADDED_DOFS`): `simulate` writes the file's
/// dofs, its disc–pad moves as the 4-dof file's (RMS to 1e-5) and the
/// chain's wave travels; `cycle` is refused with its own limit, and a 513-dof file
/// (above `MAX_TRANSIENT_DOFS`) is refused by `simulate` naming both, with no
/// output.
#[test]
fn a_150_dof_file_simulates_in_a_transient_size_and_cycles_are_refused() {
    let d = tempfile::tempdir().unwrap();
    let (text, chain) = disc_pad_with_chain(146);
    std::fs::write(d.path().join("big150.toml"), &text).unwrap();
    let human = simulate_beside_disc_pad(d.path(), "big150.toml", "b150", "0.05");
    // 150 velocities: the summary lists the 12 largest, summary.json all.
    assert!(
        human.contains("RMS velocity over the last 20 % (m/s), the largest: ")
            && human.contains("… and 138 more in summary.json"),
        "{human}"
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.path().join("b150/summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary["rms"].as_object().unwrap().len(), 150);
    let (hb, rb) = read_series(&d.path().join("b150"));
    let (h4, r4) = read_series(&d.path().join("b4"));
    // t, 150 positions, 150 velocities, the contact's four columns.
    assert_eq!(hb.len(), 1 + 300 + 4, "series.csv columns");
    let idle = |c: &String| {
        let q = c.strip_prefix('v').unwrap_or(c);
        q.strip_prefix("pad.")
            .is_some_and(|r| r.starts_with(|ch: char| ch.is_ascii_digit()))
    };
    assert!(!hb.iter().any(idle), "an idle dof was written: {hb:?}");
    assert_eq!(rb.len(), r4.len());
    for name in ["vx_d", "vx_p", "vy_d", "vy_p"] {
        let (x, y) = (rms(&h4, &r4, name), rms(&hb, &rb, name));
        // 1e-5: the error norm averages over 300 states instead of 8, so
        // the disc–pad's own error may be √(300/8) ≈ 6× rtol's.
        assert!((x - y).abs() <= 1e-5 * x, "{name}: RMS {x:e} vs {y:e}");
    }
    // A link passes the wave on in √(m/k) ≈ 0.7 ms: 0.05 s reaches c50.
    let far = col(&hb, &chain[49]);
    assert!(
        rb.iter().any(|row| row[far].abs() > 1e-9),
        "the chain's wave never reached c50"
    );
    let out = squeal(d.path(), &["cycle", "big150.toml"]);
    assert_eq!(out.status.code(), Some(2));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        e.contains("150 dofs") && e.contains("up to 128") && e.contains("512"),
        "{e}"
    );
    let (text, _) = disc_pad_with_chain(509);
    std::fs::write(d.path().join("big513.toml"), &text).unwrap();
    let out = squeal(d.path(), &["simulate", "big513.toml", "--out", "x"]);
    assert_eq!(out.status.code(), Some(2));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("513 dofs") && e.contains("up to 512"), "{e}");
    assert!(!d.path().join("x").exists());
}

#[test]
fn bad_lumped_files_exit_2_naming_element_and_key() {
    let d = tempfile::tempdir().unwrap();
    let base = std::fs::read_to_string(scenarios().join("disc-pad.toml")).unwrap();
    std::fs::write(
        d.path().join("A.mtx"),
        "%%MatrixMarket matrix coordinate real general\n3 4 1\n1 1 1.0\n",
    )
    .unwrap();
    std::fs::write(
        d.path().join("N.mtx"),
        "%%MatrixMarket matrix coordinate real general\n4 4 5\n1 1 1.0\n2 2 1.0\n3 3 1.0\n4 4 1.0\n1 2 0.5\n",
    )
    .unwrap();
    let cases: Vec<(String, &str)> = vec![
        (base.replace("on = { x_d = 1.0 }", "on = { x_q = 1.0 }"), "spring 'disc_x': on: unknown dof 'x_q'"),
        (base.replace("x_p = 0.1\ny_d", "x_p = -0.1\ny_d"), "masses: x_p = -0.1"),
        (base.replace("tangent = { x_d = 1.0, x_p = -1.0 }\n", ""), "contact 'pad': tangent: missing"),
        (
            base.replace("[solver]", "[matrices]\nM = \"A.mtx\"\n\n[solver]"),
            "matrices: M is 3×4, not square",
        ),
        (
            base.replace("[solver]", "[matrices]\nM = \"N.mtx\"\n\n[solver]"),
            "matrices: M is not symmetric",
        ),
        (
            base.replace("[solver]", "[[contact]]\nname = \"pad2\"\nnormal = { y_d = 1.0, y_p = -1.0 }\nk = 1e9\ntangent = { x_d = -2.0, x_p = 2.0 }\nV = 1.0\n\n[solver]"),
            "contact 'pad2': tangent: its stick constraint is redundant with 'pad'",
        ),
        (base.replace("k = 4.25e9", "k = -4.25e9"), "contact 'pad': k = -4250000000: must be"),
        (base.replace("f0 = 0.1", "f0 = 0.1\nbogus = 2"), "contact 'pad': unknown key 'bogus'"),
    ];
    for (i, (text, want)) in cases.iter().enumerate() {
        let f = format!("bad{i}.toml");
        std::fs::write(d.path().join(&f), text).unwrap();
        let out = squeal(d.path(), &["simulate", &f, "--out", "never"]);
        let e = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "case {i}: {e}");
        assert!(e.contains(want), "case {i}: expected '{want}' in: {e}");
        assert_eq!(e.trim().lines().count(), 1, "one line: {e}");
        assert!(!d.path().join("never").exists());
    }
    // Keys on the command line: unknown element, a value out of range.
    let f = scenarios().join("disc-pad.toml");
    let out = squeal(
        d.path(),
        &["stability", f.to_str().unwrap(), "--set", "pad.mu_k=0.1"],
    );
    assert_eq!(out.status.code(), Some(2));
    let out = squeal(
        d.path(),
        &["stability", f.to_str().unwrap(), "--set", "mass.x_p=-1"],
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("mass.x_p"));
}

#[test]
fn sweep_of_the_lumped_hoffmann_finds_the_built_ins_coalescence() {
    let d = tempfile::tempdir().unwrap();
    let f = scenarios().join("hoffmann.toml");
    let a = json(&squeal(
        d.path(),
        &[
            "sweep",
            f.to_str().unwrap(),
            "--set",
            "belt.mu_s=2",
            "--param",
            "belt.mu_k=0.1:0.5:41",
            "--json",
            "--out",
            "a",
        ],
    ));
    let b = json(&squeal(
        d.path(),
        &[
            "sweep",
            "hoffmann",
            "--param",
            "mu=0.1:0.5:41",
            "--json",
            "--out",
            "b",
        ],
    ));
    let (oa, ob) = (&a["onsets"][0], &b["onsets"][0]);
    assert_eq!(oa["coalescence"], true);
    let (x, y) = (oa["value"].as_f64().unwrap(), ob["value"].as_f64().unwrap());
    assert!((x - y).abs() <= 1e-9 * y, "{x} vs {y}");
    assert!(d.path().join("a/sweep.csv").is_file());
}

/// A two-pad brake pressed hard with high friction: a pad reaching
/// `v_rel = 0` sticks. (Before, the sign of the round-off left by projecting
/// the state onto `v_rel = 0` chose "slip on", the guard fired again at
/// once, and the run stood still until its step budget ran out, blaming
/// stiffness.)
#[test]
fn a_hard_pressed_two_pad_brake_sticks_and_slips_to_the_end() {
    let d = tempfile::tempdir().unwrap();
    let f = scenarios().join("two-pad-brake.toml");
    let mut args = vec!["simulate", f.to_str().unwrap(), "--duration", "0.02"];
    for s in [
        "pad1.V=0.05",
        "pad2.V=0.05",
        "pad1.f0=0.5",
        "pad2.f0=0.5",
        "brake_1.value=-3000",
        "brake_2.value=3000",
    ] {
        args.extend(["--set", s]);
    }
    args.extend(["--out", "o", "--no-plots"]);
    let out = ok(&squeal(d.path(), &args));
    assert!(out.contains("verdict: stick-slip"), "{out}");
    let events = std::fs::read_to_string(d.path().join("o/events.csv")).unwrap();
    let sticks = |pad: &str| {
        events
            .lines()
            .filter(|l| l.ends_with(&format!("stick,{pad}")))
            .count()
    };
    assert!(
        sticks("pad1") > 100 && sticks("pad2") > 100,
        "{} {}",
        sticks("pad1"),
        sticks("pad2")
    );
}
