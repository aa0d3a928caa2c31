//! `squeal stability [SCENARIO] [--set …] [--json] [--out DIR]`: every
//! eigenvalue of the steady-sliding state, each mode's growth rate,
//! frequency, damping ratio, dominant coordinate and complex mode shape
//! (amplitude and phase per dof; in `--json` and in `DIR/modes.csv`), and the
//! verdict (MODEL.md §5).

use crate::commands::simulate::resolve;
use crate::run::RunError;
use crate::ScenarioArgs;
use clap::Args;
use squeal_core::stability::Analysis;
use squeal_study::levers::{lever_keys, Levers};
use squeal_study::stability::document;

/// Arguments of `squeal stability`.
#[derive(Args, Debug)]
pub struct StabilityArgs {
    #[command(flatten)]
    scenario: ScenarioArgs,
    /// Print a JSON document on stdout instead of the table.
    #[arg(long)]
    json: bool,
    /// Write modes.csv (complex mode shapes of every mode) into this folder.
    #[arg(long)]
    out: Option<std::path::PathBuf>,
    /// Skip the levers (what would stop it: a search over every parameter,
    /// seconds for a few hundred dofs).
    #[arg(long)]
    no_levers: bool,
}

/// One line saying that the analysis is a reduced-basis one, if it is.
fn modal_line(an: &Analysis) -> Option<String> {
    match an.method {
        squeal_core::stability::projected::Method::Dense => None,
        squeal_core::stability::projected::Method::Projected {
            modes,
            dofs,
            basis_max_hz,
            static_vectors,
            basis: squeal_core::stability::projected::BasisKind::Modes,
            sturm_count,
        } => Some(format!(
            "projected onto the {modes} lowest undamped modes of {dofs} dofs (up to {basis_max_hz:.1} Hz{}) and {static_vectors} static-correction vectors at the contact dofs: a reduced-basis answer for the modes in that band, none above it (modal.modes / modal.cutoff_hz / modal.dense_max_dofs choose)",
            sturm_words(sturm_count)
        )),
        squeal_core::stability::projected::Method::Projected {
            modes,
            dofs,
            basis_max_hz,
            static_vectors,
            basis: squeal_core::stability::projected::BasisKind::CraigBampton,
            sturm_count,
        } => Some(format!(
            "projected onto a Craig–Bampton basis of {dofs} dofs: the {static_vectors} contact dofs kept physical and {modes} fixed-interface modes (up to {basis_max_hz:.1} Hz{}): a reduced-basis answer for the modes in that band, none above it (modal.basis / modal.modes / modal.cutoff_hz / modal.dense_max_dofs choose)",
            sturm_words(sturm_count)
        )),
    }
}

/// ", none missed: Sturm count" when the Lanczos path's count confirmed the modes.
fn sturm_words(count: Option<usize>) -> &'static str {
    if count.is_some() {
        ", none missed: Sturm count"
    } else {
        ""
    }
}

/// Run the command.
pub fn run(a: StabilityArgs) -> Result<(), RunError> {
    let sc = resolve(&a.scenario)?;
    if let Some(dest) = &a.out {
        crate::staging::check_dest_as("--out", dest)?;
    }
    if let Some(p) = squeal_study::plan::plan(&sc, "stability", 1) {
        crate::errln!("{p}");
    }
    // The analysis with the truncation error of a projected one (issue 27
    // §2), its modes computed once for both.
    let (an, convergence) = squeal_study::stability::analyse_with_convergence(&sc.model)
        .map_err(|e| squeal_study::feasible::stability_failure(&sc.model, e))?;
    if let Some(dest) = &a.out {
        let stage = crate::run::Staging::new_as("--out", dest)?;
        squeal_files::modes::write_modes_csv(&stage.path("modes.csv"), &sc.model, &an)?;
        stage.commit()?;
    }
    let levers = if a.no_levers {
        Levers::none()
    } else {
        let bar = crate::run::progress_bar(lever_keys(&sc.model).len() as u64, "searching levers");
        squeal_study::levers::search(&sc.model, &bar, &crate::run::NEVER)?
    };
    let convergence = match convergence {
        Some(Ok(c)) => Some(c),
        Some(Err(e)) => {
            crate::errln!("warning: no truncation table: {e}");
            None
        }
        None => None,
    };
    if let Some(w) = convergence.as_ref().and_then(|c| c.warning()) {
        crate::errln!("warning: {w}");
    }
    if a.json {
        let mut doc = document(&sc, &an, &levers);
        if let Some(c) = &convergence {
            doc["convergence"] = c.to_json();
        }
        crate::outln!(
            "{}",
            serde_json::to_string_pretty(&doc).map_err(|e| RunError::Io(e.to_string()))?
        );
        return Ok(());
    }
    let verdict = if an.stable {
        "STABLE: every mode is damped"
    } else if an.neutral {
        "NEUTRAL: no mode grows, but a mode is undamped (σ = 0 within the eigen-solver's round-off, 1e-12·|λ|); linear analysis cannot decide"
    } else {
        "UNSTABLE: it squeals"
    };
    crate::outln!(
        "{} ({}): steady sliding is {verdict} (max growth rate {:+.6e} 1/s)",
        sc.name,
        sc.model.name(),
        an.max_growth_rate
    );
    if let Some(line) = modal_line(&an) {
        crate::outln!("{line}");
    }
    for line in convergence.iter().flat_map(|c| c.table_lines()) {
        crate::outln!("{line}");
    }
    crate::outln!(
        "{:>3}  {:>15}  {:>15}  {:>12}  {:>14}  dominant",
        "#",
        "σ (1/s)",
        "ω (rad/s)",
        "freq (Hz)",
        "damping ratio"
    );
    for (i, e) in an.eigen.iter().enumerate() {
        crate::outln!(
            "{:>3}  {:>+15.6e}  {:>+15.6e}  {:>12.2}  {:>+14.4e}  {}{}",
            i + 1,
            e.re,
            e.im,
            e.freq_hz,
            e.damping_ratio,
            e.dominant_name,
            if e.growing {
                "  grows"
            } else if e.neutral {
                "  neutral"
            } else {
                ""
            }
        );
    }
    let ls = an.least_stable_mode();
    crate::outln!(
        "least stable mode: {:.2} Hz, dominated by {}, σ = {:+.6e} 1/s",
        ls.freq_hz,
        ls.dominant_name,
        ls.re
    );
    for c in squeal_study::stability::coupled_modes(&sc.model, &an) {
        let e = &an.eigen[c.eigenvalue];
        let parts: Vec<String> = c
            .composition
            .shares
            .iter()
            .map(|s| {
                format!(
                    "{:.0} % real mode {} ({:.2} Hz)",
                    100.0 * s.share,
                    s.mode,
                    s.freq_hz
                )
            })
            .collect();
        let at: Vec<String> = c
            .contact_dofs
            .iter()
            .map(|(d, a)| format!("{d} ({a:.2})"))
            .collect();
        crate::outln!(
            "growing mode #{} ({:.2} Hz, σ = {:+.4e} 1/s) is made of {}{}; at the contacts it moves most {}",
            c.eigenvalue + 1,
            e.freq_hz,
            e.re,
            parts.join(", "),
            if c.composition.captured < 0.99 {
                format!(" (the basis holds {:.0} % of it)", 100.0 * c.composition.captured)
            } else {
                String::new()
            },
            at.join(", ")
        );
    }
    if !a.no_levers {
        print_levers(&an, &levers);
    }
    Ok(())
}

/// The levers as text: the ranked changes that flip the verdict with their
/// windows, the changes that only move the squeal, and the largest
/// sensitivities.
fn print_levers(an: &Analysis, lv: &Levers) {
    let unstable = an.eigen.iter().any(|e| e.growing);
    if lv.levers.is_empty() {
        crate::outln!(
            "no single parameter change within ×1000 either way (inside each parameter's physical range) changes the verdict"
        );
    } else {
        crate::outln!(
            "{} by changing one parameter (all others as they are), smallest relative change first:",
            if unstable {
                "what would stop it"
            } else {
                "it would start to squeal"
            }
        );
        for l in &lv.levers {
            let rel = l.relative_change();
            let rel = if rel.is_finite() {
                format!("{:+.1} %", 100.0 * rel)
            } else {
                "from 0".to_string()
            };
            let window = if !l.stops {
                String::new()
            } else if let Some(u) = l.until {
                format!(
                    "; stable until {:.4e} (there the {:.1} Hz mode grows)",
                    u.value, u.freq_hz
                )
            } else if let Some(why) = &l.search_ended {
                format!("; stable as far as it can go ({why})")
            } else {
                format!(
                    "; stable all the way to {:.4e}, the end of the search",
                    l.searched_to
                )
            };
            crate::outln!(
                "  {} {:<16} from {:<11} to {:.6e} {} ({rel}; the {:.1} Hz mode crosses there){window}",
                l.way.word(),
                l.param,
                format!("{:.4e}", l.from),
                l.to,
                l.unit,
                l.freq_hz
            );
        }
    }
    for m in &lv.moves {
        let ing = format!("{}ing", m.way.word().trim_end_matches('e'));
        if m.already_growing {
            crate::outln!(
                "  {ing} {} stops the {:.1} Hz mode at {:.4e} {}, but the {:.1} Hz mode, growing already, goes on (σ = {:+.3e} 1/s there)",
                m.param, m.stops_hz, m.at, m.unit, m.grows_hz, m.growth_rate
            );
        } else {
            crate::outln!(
                "  {ing} {} only moves the squeal: at {:.4e} {} the {:.1} Hz mode stops growing and the {:.1} Hz mode grows instead (σ = {:+.3e} 1/s)",
                m.param, m.at, m.unit, m.stops_hz, m.grows_hz, m.growth_rate
            );
        }
    }
    let mut s: Vec<_> = lv.sensitivities.iter().collect();
    s.sort_by(|a, b| b.relative.abs().total_cmp(&a.relative.abs()));
    if !s.is_empty() {
        crate::outln!(
            "sensitivity of the {:.2} Hz mode's growth rate (σ = {:+.4e} 1/s) to a 1 % change of each parameter, largest first:",
            lv.eigenvalue.im / (2.0 * std::f64::consts::PI),
            lv.eigenvalue.re
        );
        let mag = lv.eigenvalue.norm();
        for x in s.iter().take(10) {
            crate::outln!(
                "  {:<16} {}{}",
                x.param,
                // Below the eigen-solver's round-off (NEUTRAL_TOL·|λ|): zero.
                if (0.01 * x.relative).abs() <= squeal_core::stability::NEUTRAL_TOL * mag {
                    "≈ 0 (round-off)".to_string()
                } else {
                    format!("{:+.4e} 1/s", 0.01 * x.relative)
                },
                match x.method {
                    squeal_study::levers::Method::Eigenvectors => "",
                    squeal_study::levers::Method::Coalescence =>
                        "  (at a coalescence: one-sided difference)",
                    squeal_study::levers::Method::Projected =>
                        "  (difference of the projected eigenvalue)",
                }
            );
        }
    }
    if !lv.inert.is_empty() {
        crate::outln!(
            "not in steady sliding's linearisation: {}",
            lv.inert.join(", ")
        );
    }
}
