//! The files of a nonlinear mode (`nma --out`): `nma.csv`, `summary.json`
//! and `nma.png`/`.svg` (frequency and damping ratio against the modal
//! amplitude).

use crate::{RunError, Staging};
use serde_json::Value;
use squeal_plot::{Format, Panel, Series};
use squeal_study::nma::NmaFound;
use squeal_study::scenario::Scenario;
use std::io::{BufWriter, Write};

/// Write the mode `f` of `sc`, with its JSON document `doc`, into `stage`:
/// `nma.csv` (per amplitude: `modal_amplitude`, `freq_hz`, `xi`,
/// `damping_ratio`, `amplitude_<state>`…, `residual`, `sticks`, `stick_constraint`).
pub fn write(stage: &Staging, f: &NmaFound, sc: &Scenario, doc: &Value) -> Result<(), RunError> {
    let path = stage.path("nma.csv");
    let io = |e: std::io::Error| RunError::Io(format!("cannot write {}: {e}", path.display()));
    let file = std::fs::File::create(&path).map_err(io)?;
    let mut w = BufWriter::new(file);
    let mut header: Vec<String> = ["modal_amplitude", "freq_hz", "xi", "damping_ratio"]
        .map(String::from)
        .to_vec();
    header.extend(f.names.iter().map(|s| format!("amplitude_{s}")));
    header.extend(["residual", "sticks", "stick_constraint"].map(String::from));
    writeln!(w, "{}", header.join(",")).map_err(io)?;
    for r in &f.rows {
        let mut row = vec![
            format!("{:e}", r.modal_amplitude),
            format!("{:e}", r.freq_hz),
            format!("{:e}", r.xi),
            format!("{:e}", r.damping_ratio),
        ];
        row.extend(r.amplitude.iter().map(|a| format!("{a:e}")));
        row.push(format!("{:e}", r.residual));
        row.push(r.sticks.to_string());
        row.push(r.stick_constraint.to_string());
        writeln!(w, "{}", row.join(",")).map_err(io)?;
    }
    w.flush().map_err(io)?;
    if !f.rows.is_empty() {
        let a: Vec<f64> = f.rows.iter().map(|r| r.modal_amplitude).collect();
        let hz: Vec<f64> = f.rows.iter().map(|r| r.freq_hz).collect();
        let d: Vec<f64> = f.rows.iter().map(|r| 100.0 * r.damping_ratio).collect();
        let t1 = format!(
            "{}: nonlinear mode {} (EPMC, H = {})",
            sc.name, f.mode, f.harmonics
        );
        let x = "mass-normalised modal amplitude (m·√kg)";
        let p1 = Panel::new(&t1, x, "frequency (Hz)")
            .log_x(true)
            .with_series(Series::new("frequency", &a, &hz).colour(0));
        let p2 = Panel::new("damping", x, "modal damping ratio (%)")
            .log_x(true)
            .with_series(Series::new("damping ratio", &a, &d).colour(1));
        squeal_plot::line_panels(
            stage.dir().join("nma"),
            &[Format::Png, Format::Svg],
            squeal_plot::SIZE_MULTI,
            &[p1, p2],
        )
        .map_err(|e| RunError::Io(format!("plot: {e}")))?;
    }
    crate::output::write_json(doc, &stage.path("summary.json"))
}
