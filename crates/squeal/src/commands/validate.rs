//! `squeal validate [--json] [FILTER]`: squeal's benchmark cases against
//! analytic, published or independently computed references
//! (`squeal_study::validate`); exit code 1 when any case fails.

use crate::run::RunError;
use clap::Args;
use serde_json::json;
use squeal_study::validate;

/// Arguments of `squeal validate`.
#[derive(Args, Debug)]
pub struct ValidateArgs {
    /// Run only the cases whose name contains this text.
    #[arg(value_name = "NAME-FILTER")]
    filter: Option<String>,
    /// Print {"cases": [{"name", "kind", "reference", "source", "value", "error",
    /// "tolerance", "pass", …}], "passed", "failed"} as JSON on stdout.
    #[arg(long)]
    json: bool,
}

/// Run the command.
pub fn run(a: ValidateArgs) -> Result<(), RunError> {
    let filter = a.filter.as_deref();
    let total = validate::specs()
        .iter()
        .filter(|s| filter.is_none_or(|f| s.name.contains(f)))
        .count();
    if total == 0 {
        return Err(RunError::Input(squeal_study::InputError(format!(
            "no validation case's name contains {:?}",
            filter.unwrap_or("")
        ))));
    }
    let bar = crate::run::progress_bar(total as u64, "validate");
    let cases = validate::run(filter, &bar);
    let passed = cases.iter().filter(|c| c.pass).count();
    let failed = cases.len() - passed;
    if a.json {
        let doc = json!({ "cases": cases, "passed": passed, "failed": failed });
        crate::outln!(
            "{}",
            serde_json::to_string_pretty(&doc).map_err(|e| RunError::Io(e.to_string()))?
        );
    } else {
        crate::outln!(
            "{:<28} {:<11} {:>16} {:>16} {:>9} {:>9}  pass",
            "name",
            "kind",
            "reference",
            "value",
            "error",
            "tolerance"
        );
        for c in &cases {
            let kind = serde_json::to_value(c.kind)
                .ok()
                .and_then(|v| v.as_str().map(str::to_string))
                .unwrap_or_default();
            crate::outln!(
                "{:<28} {:<11} {:>16} {:>16} {:>9.2e} {:>9.0e}  {}",
                c.name,
                kind,
                number(c.reference),
                number(c.value),
                c.error,
                c.tolerance,
                if c.pass { "pass" } else { "FAIL" }
            );
            for line in wrap(&format!("{} [{}]", c.quantity, c.unit)) {
                crate::outln!("{line}");
            }
            for line in wrap(&format!("reference: {}", c.source)) {
                crate::outln!("{line}");
            }
            if let Some(d) = &c.detail {
                for line in wrap(&format!("failed: {d}")) {
                    crate::outln!("{line}");
                }
            }
        }
        crate::outln!("{passed} of {} cases passed", cases.len());
    }
    if failed > 0 {
        return Err(RunError::Io(format!(
            "{failed} of {} validation cases failed",
            cases.len()
        )));
    }
    Ok(())
}

/// `text` in lines of at most 100 characters, indented by four spaces
/// (six on continuation lines), broken at spaces.
fn wrap(text: &str) -> Vec<String> {
    let mut lines = Vec::new();
    let mut line = String::from("    ");
    for word in text.split_whitespace() {
        let fresh = line.trim().is_empty();
        if !fresh && line.chars().count() + 1 + word.chars().count() > 100 {
            lines.push(std::mem::replace(&mut line, String::from("      ")));
        }
        if !line.trim().is_empty() {
            line.push(' ');
        }
        line.push_str(word);
    }
    if !line.trim().is_empty() {
        lines.push(line);
    }
    lines
}

/// A case's number to 10 significant digits: fixed-point between 0.01 and
/// 10⁶, scientific outside (a period of 48 µs keeps its digits).
fn number(x: f64) -> String {
    if x != 0.0 && x.is_finite() && !(1e-2..1e6).contains(&x.abs()) {
        format!("{x:.9e}")
    } else {
        format!("{x:.10}")
    }
}
