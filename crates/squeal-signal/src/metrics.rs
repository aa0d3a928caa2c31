//! Scalar summaries of a run: RMS, dominant frequency and a one-word verdict.

use std::fmt;

use crate::envelope::hilbert_envelope;
use crate::error::{check_rate, check_signal, invalid, Result, SignalError};
use crate::growth::{fit_growth_rate, DB_PER_NEPER};
use crate::peaks::{find_peaks, PeakOptions};
use crate::spectrum::{welch, WelchOptions};

/// Root mean square `sqrt(Σ x²/N)` (the mean is *not* removed).
///
/// Errors: empty signal, NaN/inf samples.
pub fn rms(x: &[f64]) -> Result<f64> {
    check_signal(x)?;
    Ok((x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64).sqrt())
}

/// [`rms`] of the last `ceil(fraction·N)` samples (at least one), e.g. `0.25` for the last
/// quarter of a run, where a limit cycle has settled.
///
/// Errors: as [`rms`], and `fraction` outside `(0, 1]`.
pub fn rms_tail(x: &[f64], fraction: f64) -> Result<f64> {
    check_signal(x)?;
    if !(fraction > 0.0 && fraction <= 1.0) {
        return Err(invalid(
            "fraction",
            format!("must be in (0, 1], got {fraction}"),
        ));
    }
    let m = ((fraction * x.len() as f64).ceil() as usize).clamp(1, x.len());
    rms(&x[x.len() - m..])
}

/// Frequency (Hz) of the strongest peak of the Hann-windowed Welch PSD with default
/// [`WelchOptions`] (segments of `min(8192, N)` samples, 50 % overlap, mean removed),
/// refined by parabolic interpolation ([`find_peaks`]). `Ok(None)` if there is no peak
/// (e.g. a constant signal).
///
/// Errors: as [`welch`] (empty, NaN/inf, `fs ≤ 0`, fewer than 2 samples).
pub fn dominant_frequency(x: &[f64], fs: f64) -> Result<Option<f64>> {
    let spec = welch(x, fs, &WelchOptions::default())?;
    Ok(find_peaks(&spec, 1, &PeakOptions::default())
        .first()
        .map(|p| p.freq))
}

/// One-word summary of a run (see [`classify_with`] for the rule).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Verdict {
    /// The vibration dies out: stable.
    Decays,
    /// Still growing exponentially at the end of the run: unstable, not yet saturated.
    Grows,
    /// Steady oscillation at the end: a (smooth) limit cycle, i.e. squeal.
    LimitCycle,
    /// Steady oscillation with stick or velocity-reversal events in the tail.
    StickSlip,
}

impl Verdict {
    /// `"decays"`, `"grows"`, `"limit-cycle"` or `"stick-slip"`.
    pub fn as_str(self) -> &'static str {
        match self {
            Verdict::Decays => "decays",
            Verdict::Grows => "grows",
            Verdict::LimitCycle => "limit-cycle",
            Verdict::StickSlip => "stick-slip",
        }
    }
}

impl fmt::Display for Verdict {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Thresholds of [`classify_with`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VerdictOptions {
    /// Fraction trimmed at each end of the envelope (Hilbert end effects); default 0.02.
    pub edge_fraction: f64,
    /// Fraction of the (trimmed) run forming the tail; default 0.25.
    pub tail_fraction: f64,
    /// The tail is steady when its fitted level change is within ± this many dB;
    /// default 1 dB.
    pub steady_tol_db: f64,
    /// A steady tail at least this many dB below the run's peak level counts as decayed
    /// (settled on a numerical noise floor); default 40 dB.
    pub decayed_db: f64,
    /// A steady tail is stick-slip when the caller's stick/reversal fraction exceeds this;
    /// default 0.01.
    pub stick_threshold: f64,
}

impl Default for VerdictOptions {
    fn default() -> Self {
        Self {
            edge_fraction: 0.02,
            tail_fraction: 0.25,
            steady_tol_db: 1.0,
            decayed_db: 40.0,
            stick_threshold: 0.01,
        }
    }
}

/// A [`Verdict`] with the numbers it was decided from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Classification {
    /// The verdict.
    pub verdict: Verdict,
    /// Level change of the envelope across the tail from a log-linear fit, in dB.
    pub tail_change_db: f64,
    /// Fitted exponential rate of the envelope over the tail, 1/s.
    pub tail_rate: f64,
    /// Peak block level of the envelope minus the mean tail level, in dB (≥ 0).
    pub drop_from_peak_db: f64,
}

/// [`classify_with`] with default [`VerdictOptions`].
pub fn classify(x: &[f64], fs: f64, stick_or_reversal_fraction: f64) -> Result<Verdict> {
    classify_with(
        x,
        fs,
        stick_or_reversal_fraction,
        &VerdictOptions::default(),
    )
    .map(|c| c.verdict)
}

/// Classifies a velocity signal `x` (sampled at `fs`) from its Hilbert envelope `A`.
///
/// `stick_or_reversal_fraction` ∈ `[0, 1]` is supplied by the caller, who knows the contact
/// state: the fraction of the tail spent sticking or with reversed relative velocity.
///
/// Rule (`A` of `x − median(x)`, `edge_fraction` trimmed at each end, floored 300 dB below its
/// maximum; the tail is the last `tail_fraction` of what remains, its envelope recomputed from
/// the tail alone to keep leakage from a large early part out; `Δ` is the tail's level
/// change `σ_tail·T_tail·20/ln 10` dB from a log-linear fit ([`fit_growth_rate`]); the peak
/// level is the highest of 20 block means of `ln A`):
/// 1. `x` constant (zero envelope) → [`Verdict::Decays`];
/// 2. `Δ > +steady_tol_db` → [`Verdict::Grows`];
/// 3. `Δ < −steady_tol_db` → [`Verdict::Decays`];
/// 4. steady tail whose mean level is `≥ decayed_db` below the peak → [`Verdict::Decays`];
/// 5. steady tail with `stick_or_reversal_fraction > stick_threshold` → [`Verdict::StickSlip`];
/// 6. otherwise → [`Verdict::LimitCycle`].
///
/// Errors: empty/non-finite signal, `fs ≤ 0`, fewer than 64 samples, fraction outside
/// `[0, 1]`, options out of range.
pub fn classify_with(
    x: &[f64],
    fs: f64,
    stick_or_reversal_fraction: f64,
    opts: &VerdictOptions,
) -> Result<Classification> {
    check_signal(x)?;
    check_rate(fs)?;
    let sf = stick_or_reversal_fraction;
    if !(0.0..=1.0).contains(&sf) {
        return Err(invalid(
            "stick_or_reversal_fraction",
            format!("must be in [0, 1], got {sf}"),
        ));
    }
    if !(opts.edge_fraction.is_finite() && (0.0..0.25).contains(&opts.edge_fraction)) {
        return Err(invalid("edge_fraction", "must be in [0, 0.25)"));
    }
    if !(opts.tail_fraction > 0.0 && opts.tail_fraction <= 1.0) {
        return Err(invalid("tail_fraction", "must be in (0, 1]"));
    }
    for (name, v) in [
        ("steady_tol_db", opts.steady_tol_db),
        ("decayed_db", opts.decayed_db),
        ("stick_threshold", opts.stick_threshold),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(invalid(name, format!("must be finite and >= 0, got {v}")));
        }
    }
    let n = x.len();
    if n < 64 {
        return Err(SignalError::TooShort { need: 64, got: n });
    }
    let offset = crate::growth::median(x);
    let centred: Vec<f64> = x.iter().map(|v| v - offset).collect();
    let env = hilbert_envelope(&centred)?;
    let trim = (opts.edge_fraction * n as f64).ceil() as usize;
    let env = &env[trim..n - trim];
    let peak = env.iter().copied().fold(0.0, f64::max);
    if peak <= 0.0 {
        return Ok(Classification {
            verdict: Verdict::Decays,
            tail_change_db: 0.0,
            tail_rate: 0.0,
            drop_from_peak_db: 0.0,
        });
    }
    let floor = peak * 1e-15;
    let ln_env = |e: f64| e.max(floor).ln();
    let len = env.len();
    let bs = (len / 20).max(1);
    let peak_ln = env
        .chunks(bs)
        .map(|c| c.iter().map(|&v| ln_env(v)).sum::<f64>() / c.len() as f64)
        .fold(f64::NEG_INFINITY, f64::max);
    // The tail's envelope is recomputed from the tail alone (plus a lead-in of a tenth of
    // its length, discarded), so Hilbert leakage from a much larger early part of a decaying
    // run cannot mask the tail's own trend.
    let tail_len = ((opts.tail_fraction * len as f64).ceil() as usize).clamp(3, len);
    let t1 = n - trim;
    let t0 = t1 - tail_len;
    let s0 = t0.saturating_sub(tail_len / 10);
    let tail_env: Vec<f64> = hilbert_envelope(&centred[s0..])?
        .into_iter()
        .map(|e| e.max(floor))
        .collect();
    let tail = t0 - s0..t1 - s0;
    let tail_mean_ln = tail_env[tail.clone()].iter().map(|v| v.ln()).sum::<f64>() / tail_len as f64;
    let fit = fit_growth_rate(&tail_env, fs, tail)?;
    let tail_change_db = fit.change_db();
    let drop_from_peak_db = ((peak_ln - tail_mean_ln) * DB_PER_NEPER).max(0.0);
    let verdict = if tail_change_db > opts.steady_tol_db {
        Verdict::Grows
    } else if tail_change_db < -opts.steady_tol_db || drop_from_peak_db >= opts.decayed_db {
        Verdict::Decays
    } else if sf > opts.stick_threshold {
        Verdict::StickSlip
    } else {
        Verdict::LimitCycle
    };
    Ok(Classification {
        verdict,
        tail_change_db,
        tail_rate: fit.rate,
        drop_from_peak_db,
    })
}
