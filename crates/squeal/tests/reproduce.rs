//! `squeal reproduce` end to end at reduced duration.

use std::process::Command;

/// Run `reproduce` at a tenth of the shipped durations with `threads` rayon threads.
fn reproduce(dir: &std::path::Path, out: &str, threads: &str, extra: &[&str]) {
    let res = Command::new(env!("CARGO_BIN_EXE_squeal"))
        .current_dir(dir)
        .env("RAYON_NUM_THREADS", threads)
        .args(["reproduce", "--out", out, "--duration-scale", "0.1"])
        .args(extra)
        .output()
        .unwrap();
    assert!(
        res.status.success(),
        "{}",
        String::from_utf8_lossy(&res.stderr)
    );
}

/// A table row's fields by column name (the question is the only quoted field).
fn row(table: &str, set: usize) -> std::collections::HashMap<String, String> {
    let header: Vec<&str> = table.lines().next().unwrap().split(',').collect();
    let line = table.lines().nth(set).unwrap();
    let (_, after) = line.rsplit_once('"').unwrap();
    let fields: Vec<&str> = [line.split(',').next().unwrap(), "q"]
        .into_iter()
        .chain(after.trim_start_matches(',').split(','))
        .collect();
    assert_eq!(fields.len(), header.len(), "{line}");
    header
        .iter()
        .zip(fields)
        .map(|(h, f)| (h.to_string(), f.to_string()))
        .collect()
}

#[test]
fn reproduce_writes_the_table_the_conclusions_and_the_report() {
    let d = tempfile::tempdir().unwrap();
    reproduce(d.path(), "rep", "2", &[]);
    let dir = d.path().join("rep");
    let table = std::fs::read_to_string(dir.join("table.csv")).unwrap();
    let mut lines = table.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(table.lines().count(), 41, "a header and exactly 40 rows");
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    // Set 1 (V = 0, undamped): the normal spectrum peaks at the disc's normal
    // natural frequency, within one bin, and the tangential motion is zero.
    let row1 = table.lines().nth(1).unwrap();
    // The question is the only quoted field; split the rest after it.
    let after = row1.rsplit_once('"').unwrap().1;
    let fields: Vec<&str> = std::iter::once("1")
        .chain(std::iter::once("q"))
        .chain(after.trim_start_matches(',').split(','))
        .collect();
    let f_n: f64 = fields[col("normal_hz")].parse().unwrap();
    let k = (4.25e9f64, 8.0e6f64);
    let (a, b, c, dd) = ((k.1 + k.0) / 1.0, -k.0 / 1.0, -k.0 / 0.1, k.0 / 0.1);
    let tr = a + dd;
    let w2 = 0.5 * (tr - (tr * tr - 4.0 * (a * dd - b * c)).sqrt());
    let want = w2.sqrt() / (2.0 * std::f64::consts::PI);
    // 0.05 s at 200 kHz: one Welch segment of 10001 samples, bins of 20 Hz.
    assert!(
        (f_n - want).abs() <= 200_000.0 / 10_001.0,
        "{f_n} vs {want}"
    );
    assert_eq!(fields[col("tangential_zero")], "true");
    assert_eq!(fields[col("linear")], "none", "no steady sliding at V = 0");
    let cj: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("conclusions.json")).unwrap())
            .unwrap();
    let cs = cj.as_array().unwrap();
    assert_eq!(cs.len(), 7);
    for (i, c) in cs.iter().enumerate() {
        assert_eq!(c["id"], i + 1);
        assert!(c["held"].is_boolean());
        assert!(c["claim"].as_str().unwrap().len() > 40);
        assert!(c["evidence"].as_str().unwrap().len() > 40, "{c}");
    }
    // Conclusion 3 is checked against an eigenvalue sweep, not only the sets —
    // and the sweep is linear, so it holds at any duration.
    let e3 = cs[2]["evidence"].as_str().unwrap();
    assert!(e3.contains("Sweep: 800 points"), "{e3}");
    assert_eq!(cs[2]["held"], true);
    let html = std::fs::read_to_string(dir.join("report.html")).unwrap();
    assert!(html.contains("map.png") && html.contains("figures/set01/triplet.png"));
    assert!(std::fs::read_to_string(dir.join("report.md"))
        .unwrap()
        .contains("scaled by 0.1"));
    for f in [
        "map.png",
        "figures/set01/triplet.png",
        "figures/set40/phase.png",
    ] {
        assert!(dir.join(f).is_file(), "{f}");
    }

    // Graded verdicts, with `held` kept as a bool that agrees with the grade.
    let grades = [
        "held",
        "held qualitatively",
        "held by another mechanism",
        "refuted",
        "outside the model",
    ];
    for c in cs {
        let g = c["grade"].as_str().unwrap();
        assert!(grades.contains(&g), "{g}");
        assert_eq!(c["held"], g.starts_with("held"), "{c}");
    }
    let md = std::fs::read_to_string(dir.join("report.md")).unwrap();
    let headline = md
        .lines()
        .find(|l| l.starts_with("## Conclusions: "))
        .unwrap();
    assert!(!headline.contains(" of 7"), "{headline}");
    for g in grades {
        assert!(md.contains(&format!("- **{g}**: ")), "grade {g} defined");
    }
    for w in [
        "decays",
        "grows",
        "limit-cycle",
        "stick-slip",
        "neutral",
        "lift-off",
        "out-of-range",
    ] {
        assert!(md.contains(&format!("- **{w}**: ")), "verdict {w} defined");
    }
    assert!(!md.contains("integrated exactly"));

    // C7: thresholds from a sweep of ≥ 30 negative α values (plus positive ones),
    // every 1 % threshold found below |α| = 1000 for the modes that change.
    let d7 = &cs[6]["data"];
    assert!(d7["alpha_values_negative"].as_u64().unwrap() >= 30, "{d7}");
    assert!(d7["alpha_values_positive"].as_u64().unwrap() >= 1, "{d7}");
    let first = d7["modes"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|m| m["sigma_1pct_abs_alpha"].as_f64())
        .fold(f64::INFINITY, f64::min);
    assert!(first < 1000.0 && first > 10.0, "{first}");
    for m in d7["modes"].as_array().unwrap() {
        if m["mode"] == "x_p" || m["mode"] == "x_d" || m["mode"] == "y_p" {
            let a = m["sigma_1pct_abs_alpha"].as_f64().unwrap();
            assert!(a < 1000.0, "{m}");
        }
    }

    // Set 40 leaves the model: never "decays", and flagged in the table.
    let table = std::fs::read_to_string(dir.join("table.csv")).unwrap();
    let r40 = row(&table, 40);
    assert_ne!(r40["verdict"], "decays");
    assert_eq!(r40["valid"], "false");
    assert!(
        md.contains("| ⚠ out-of-range (outside the model) |")
            || md.contains("| ⚠ lift-off (outside the model) |"),
        "flagged in the report's table"
    );
    // Set 15's squeal is the pad's tangential mode at 20.75 kHz.
    let r15 = row(&table, 15);
    assert_eq!(r15["squeal_coordinate"], "x_p");
    let f: f64 = r15["squeal_frequency_hz"].parse().unwrap();
    assert!((f - 20_751.0).abs() <= 0.005 * 20_751.0, "{f}");
    assert!(r15["squeal_level_db"].parse::<f64>().is_ok());
    // How loud: the disc faces (y_d) radiate; a squealing set is loud.
    let erp: f64 = r15["erp_db"].parse().unwrap();
    let dba: f64 = r15["spl_dba"].parse().unwrap();
    assert!(erp > 60.0 && dba > 40.0 && dba < erp, "{erp} {dba}");
    assert!(
        md.contains("Sets that squeal: ") && md.contains("15 (x_p 2075"),
        "squeal in the report"
    );
    // Quiet sets leave the squeal columns empty.
    let r29 = row(&table, 29);
    assert_eq!(r29["squeal_coordinate"], "");
    assert_eq!(r29["squeal_frequency_hz"], "");
    // The pad's velocity and spectrum beside the thesis's disc panels.
    let svg = std::fs::read_to_string(dir.join("figures/set15/triplet.svg")).unwrap();
    for s in ["vx_d", "vy_d", "vx_p"] {
        assert!(svg.contains(s), "triplet shows {s}");
    }
    assert!(cs[6]["evidence"].as_str().unwrap().contains("Set 39"));

    // C5 counts sticks and reversals separately, with the stick window.
    let d5 = &cs[4]["data"];
    assert!(d5["sticks"].is_u64() && d5["reversals"].is_u64(), "{d5}");
    let w = d5["stick_window_m"].as_f64().unwrap();
    assert!((w - 0.1 * 500.0 / 1.7e9).abs() < 1e-12, "{w}");
    let e5 = cs[4]["evidence"].as_str().unwrap();
    assert!(
        e5.contains("true sticks against") && e5.contains("thesis's flag"),
        "{e5}"
    );

    // C4: the model's destabilising term N·f0·f1·(1 − V/Uc) at N = 500, V = 1.
    let d4 = &cs[3]["data"];
    let term = d4["destabilising_term_kg_s"]["N500_V1"].as_f64().unwrap();
    let want = 500.0 * 0.1 / 15.0 * (1.0 - 1.0 / (50.0 / 3.0));
    assert!((term - want).abs() <= 0.01 * want, "{term} vs {want}");
    assert!((want - 3.1333).abs() < 1e-3);
    assert!(cs[3]["evidence"].as_str().unwrap().contains("30–100 kg/s"));
    assert!(cs[3]["evidence"].as_str().unwrap().contains("factor f0"));

    // C6: a c_px sweep across c_px*: the disc collapses below it, grows at its
    // eigenvalue rate above it, and its eigenvalue does not depend on c_px.
    let d6 = &cs[5]["data"];
    let c_star = d6["c_px_star"].as_f64().unwrap();
    assert!((c_star - want).abs() < 1e-9 * want, "{c_star}");
    let sweep = d6["sweep"].as_array().unwrap();
    let below: Vec<&serde_json::Value> = sweep
        .iter()
        .filter(|p| p["c_px"].as_f64().unwrap() < c_star)
        .collect();
    let above: Vec<&serde_json::Value> = sweep
        .iter()
        .filter(|p| p["c_px"].as_f64().unwrap() > c_star)
        .collect();
    assert!(below.len() >= 2 && above.len() >= 2, "{d6}");
    for p in below {
        assert!(p["saturated_at_s"].is_f64(), "{p}");
        assert!(
            p["disc_envelope_rate"].as_f64().unwrap() < -1.0,
            "collapse: {p}"
        );
    }
    for p in above {
        assert!(p["saturated_at_s"].is_null(), "{p}");
        let (r, s) = (
            p["disc_envelope_rate"].as_f64().unwrap(),
            p["sigma_disc"].as_f64().unwrap(),
        );
        assert!(
            (r - s).abs() < 0.02 * s && (s - 1.0667).abs() < 1e-3,
            "growth: {p}"
        );
    }
    assert!(d6["disc_eigenvalue_max_relative_change"].as_f64().unwrap() < 1e-6);

    // C3 also after a large kick above Uc.
    let d3 = &cs[2]["data"]["kick"];
    assert!(
        d3["V"].as_f64().unwrap() > 50.0 / 3.0 && d3["reversals"].as_u64().unwrap() > 0,
        "{d3}"
    );
    assert!(d3["disc_rate"].as_f64().unwrap() < 0.0 && d3["pad_rate"].as_f64().unwrap() < 0.0);

    // The map marks only the sets that share its parameters.
    assert!(
        md.contains("marked, at their (V, N): 15, 16, 17, 18, 19, 20, 33, 36."),
        "map note"
    );
    assert!(md.contains("429 Hz against the thesis's \"around 450 Hz\""));
    assert!(md.contains("0.4/0.7"));
    // The thesis's spectral quantity for set 1, (m/s)²: the step load N rings the
    // coupled normal mode (disc + pad, M = 1.1 kg, k_dy = 8e6 N/m) with velocity
    // amplitude N·ω/k_dy, so A² = (N·ω/k_dy)².
    let a2: f64 = md
        .split("Welch segments — is ")
        .nth(1)
        .and_then(|t| t.split(" J/kg").next())
        .unwrap()
        .parse()
        .unwrap();
    let w = (8.0e6f64 / 1.1).sqrt();
    let exact = (500.0 * w / 8.0e6).powi(2);
    assert!((a2 - exact).abs() < 0.02 * exact, "{a2} vs {exact}");

    // Byte-identical with one thread, and no wall-clock time anywhere in it.
    reproduce(d.path(), "rep1", "1", &[]);
    for f in ["report.md", "report.html", "table.csv", "conclusions.json"] {
        let a = std::fs::read(dir.join(f)).unwrap();
        let b = std::fs::read(d.path().join("rep1").join(f)).unwrap();
        assert!(a == b, "{f} differs between 1 and 2 threads");
    }
}
