//! `squeal reproduce` end to end at reduced duration.

use std::process::Command;

#[test]
fn reproduce_writes_the_table_the_conclusions_and_the_report() {
    let d = tempfile::tempdir().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_squeal"))
        .current_dir(d.path())
        .args(["reproduce", "--out", "rep", "--duration-scale", "0.1"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
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
}
