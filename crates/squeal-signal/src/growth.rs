//! Exponential growth / decay rates from the envelope.
//!
//! A linearly unstable mode grows like `A(t) = A₀·e^{σt}` until nonlinearity saturates it;
//! `σ` (1/s) is the real part of the unstable eigenvalue. It is estimated as the
//! least-squares slope of `ln A(t)`, with `A` the Hilbert envelope. The window-finding logic
//! is specific to this project and written by hand.

use std::ops::Range;

use crate::envelope::hilbert_envelope;
use crate::error::{check_rate, check_signal, invalid, Result, SignalError};

/// dB per neper for amplitude quantities: `20/ln 10`.
pub const DB_PER_NEPER: f64 = 8.685_889_638_065_035;

/// Result of a log-linear least-squares fit `ln A(t) ≈ ln A₀ + σ·t`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GrowthFit {
    /// Slope `σ` in 1/s (> 0 growing, < 0 decaying). Amplitude changes by
    /// `σ·DB_PER_NEPER` dB per second.
    pub rate: f64,
    /// Intercept `ln A₀` at `t = 0` (the first sample of the envelope passed in).
    pub ln_amp0: f64,
    /// Coefficient of determination `R² = 1 − SS_res/SS_tot` of the fit of `ln A` (1 for a
    /// perfect exponential; defined as 1 when `ln A` is constant).
    pub r_squared: f64,
    /// Start of the fitted window in seconds (time of its first sample).
    pub t_start: f64,
    /// End of the fitted window in seconds (time of its last sample).
    pub t_end: f64,
    /// Number of samples fitted.
    pub n_points: usize,
}

impl GrowthFit {
    /// Amplitude change across the fitted window in dB: `σ·(t_end − t_start)·DB_PER_NEPER`.
    pub fn change_db(&self) -> f64 {
        self.rate * (self.t_end - self.t_start) * DB_PER_NEPER
    }
}

/// Least-squares slope of `ln(envelope[i])` against `t_i = i/fs` over the sample indices in
/// `window` (ordinary least squares: `σ = Σ(t−t̄)(y−ȳ) / Σ(t−t̄)²`, `y = ln envelope`).
///
/// Errors: `fs ≤ 0`; window empty, out of range or shorter than 3 samples; a non-finite or
/// non-positive envelope value inside the window.
pub fn fit_growth_rate(envelope: &[f64], fs: f64, window: Range<usize>) -> Result<GrowthFit> {
    check_rate(fs)?;
    if envelope.is_empty() {
        return Err(SignalError::EmptySignal);
    }
    if window.start >= window.end || window.end > envelope.len() {
        return Err(invalid(
            "window",
            format!(
                "{}..{} is empty or outside 0..{}",
                window.start,
                window.end,
                envelope.len()
            ),
        ));
    }
    let n = window.len();
    if n < 3 {
        return Err(SignalError::TooShort { need: 3, got: n });
    }
    let seg = &envelope[window.clone()];
    if let Some((i, &v)) = seg.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(SignalError::NonFinite {
            index: window.start + i,
            value: v,
        });
    }
    if let Some((i, &v)) = seg.iter().enumerate().find(|(_, v)| **v <= 0.0) {
        return Err(SignalError::NonPositiveEnvelope {
            index: window.start + i,
            value: v,
        });
    }
    // Centred sums for numerical stability: t measured in samples from the window centre.
    let nf = n as f64;
    let ybar = seg.iter().map(|v| v.ln()).sum::<f64>() / nf;
    let ic = (nf - 1.0) / 2.0;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (i, v) in seg.iter().enumerate() {
        let dx = i as f64 - ic;
        sxy += dx * (v.ln() - ybar);
        sxx += dx * dx;
    }
    let slope_per_sample = sxy / sxx;
    let (mut ss_res, mut ss_tot) = (0.0, 0.0);
    for (i, v) in seg.iter().enumerate() {
        let dy = v.ln() - ybar;
        let r = dy - slope_per_sample * (i as f64 - ic);
        ss_res += r * r;
        ss_tot += dy * dy;
    }
    let r_squared = if ss_tot > 0.0 {
        1.0 - ss_res / ss_tot
    } else {
        1.0
    };
    let rate = slope_per_sample * fs;
    let t_centre = (window.start as f64 + ic) / fs;
    Ok(GrowthFit {
        rate,
        ln_amp0: ybar - rate * t_centre,
        r_squared,
        t_start: window.start as f64 / fs,
        t_end: (window.end - 1) as f64 / fs,
        n_points: n,
    })
}

/// Which way the envelope goes in the window chosen by [`growth_rate_linear_part`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Exponential growth (fit taken before saturation).
    Growing,
    /// Exponential decay.
    Decaying,
    /// No change larger than `GrowthOptions::min_change_db`: the whole trimmed record is fitted.
    Flat,
}

/// Options of [`growth_rate_linear_part`]. Levels are in dB of the envelope amplitude.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GrowthOptions {
    /// Fraction of the record trimmed at *each* end before anything else, to drop the
    /// Hilbert end effects (default 0.05).
    pub edge_fraction: f64,
    /// Number of blocks whose mean `ln A` is used to locate the window (default 200).
    pub blocks: usize,
    /// The growing fit stops where the envelope first comes within this many dB of its
    /// maximum (default 20 dB: for a cubic saturation `Ȧ = σA(1 − A²/A_s²)` the local rate
    /// there is still 99 % of `σ`). Capped at a third of the total rise.
    pub saturation_margin_db: f64,
    /// Margin in dB kept above the lowest level (start of growth, end of decay, where noise
    /// or leakage dominates) and below the peak at the start of a decay (default 6 dB).
    /// Capped at a third of the total change.
    pub floor_margin_db: f64,
    /// Minimum rise or fall (dB) to call the record growing or decaying (default 3 dB).
    pub min_change_db: f64,
}

impl Default for GrowthOptions {
    fn default() -> Self {
        Self {
            edge_fraction: 0.05,
            blocks: 200,
            saturation_margin_db: 20.0,
            floor_margin_db: 6.0,
            min_change_db: 3.0,
        }
    }
}

/// Growth-rate estimate over the automatically chosen linear part of `ln A(t)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GrowthEstimate {
    /// Direction of the record's main trend.
    pub phase: Phase,
    /// The fit over the chosen window (times in seconds from the start of `x`).
    pub fit: GrowthFit,
    /// Total rise (growing) or fall (decaying) of the block-mean envelope in dB.
    pub total_change_db: f64,
}

/// Finds the exponentially growing (or decaying) part of `x` and fits its rate.
///
/// Rule (all on `y = ln A`, `A` = Hilbert envelope of `x − median(x)`; the median, not the
/// mean, because the mean of an exponentially growing oscillation is dominated by its last
/// cycles and would leave a large offset relative to its early, small part):
/// 1. trim `edge_fraction` of the record at each end (Hilbert end effects);
/// 2. average `y` over `blocks` equal blocks; let `M` be the block maximum,
///    `rise = M − min(blocks before M)`, `fall = M − min(blocks after M)`;
/// 3. if `max(rise, fall) < min_change_db` → [`Phase::Flat`], fit the whole trimmed record;
/// 4. growing (`rise ≥ fall`): from the minimum before `M`, start at the first block at least
///    `floor_margin_db` above it, stop at the first block within `saturation_margin_db` of `M`;
/// 5. decaying: from `M`, start at the first block `floor_margin_db` below `M`, stop at the
///    first block within `floor_margin_db` of the minimum after `M`;
/// 6. fit [`fit_growth_rate`] on the full-rate envelope over that window;
/// 7. unless flat, refit on a leakage-corrected envelope of the window (flattened by the
///    first-pass rate before the Hilbert transform; see the source of `refine`).
///
/// Errors: empty or non-finite signal, `fs ≤ 0`, fewer than 16 samples, an identically
/// constant signal (no envelope), options out of range.
pub fn growth_rate_linear_part(x: &[f64], fs: f64, opts: &GrowthOptions) -> Result<GrowthEstimate> {
    check_signal(x)?;
    check_rate(fs)?;
    validate(opts)?;
    let n = x.len();
    if n < 16 {
        return Err(SignalError::TooShort { need: 16, got: n });
    }
    let offset = median(x);
    let centred: Vec<f64> = x.iter().map(|v| v - offset).collect();
    let env = hilbert_envelope(&centred)?;
    let peak = env.iter().copied().fold(0.0, f64::max);
    if peak <= 0.0 {
        return Err(invalid(
            "x",
            "signal is constant (zero envelope): no growth rate",
        ));
    }
    // Floor 300 dB below the peak so ln() is finite where the envelope is exactly zero.
    let floor = peak * 1e-15;
    let env: Vec<f64> = env.into_iter().map(|e| e.max(floor)).collect();

    let trim = ((opts.edge_fraction * n as f64).ceil() as usize).min((n - 4) / 2);
    let (i0, i1) = (trim, n - trim);
    let len = i1 - i0;
    let nb = opts.blocks.min(len / 2).max(1);
    let bs = len / nb;
    let y: Vec<f64> = (0..nb)
        .map(|b| {
            let s = &env[i0 + b * bs..i0 + (b + 1) * bs];
            s.iter().map(|v| v.ln()).sum::<f64>() / bs as f64
        })
        .collect();
    let to_np = |db: f64| db / DB_PER_NEPER;

    let b_max = argmax(&y);
    let b_min_before = argmin(&y[..=b_max]);
    let b_min_after = b_max + argmin(&y[b_max..]);
    let rise = y[b_max] - y[b_min_before];
    let fall = y[b_max] - y[b_min_after];

    let (phase, blocks, change) = if rise.max(fall) < to_np(opts.min_change_db) {
        (Phase::Flat, 0..nb, rise.max(fall))
    } else if rise >= fall {
        let floor_m = to_np(opts.floor_margin_db).min(rise / 3.0);
        let sat_m = to_np(opts.saturation_margin_db).min(rise / 3.0);
        let lo = y[b_min_before] + floor_m;
        let hi = y[b_max] - sat_m;
        let start = (b_min_before..=b_max)
            .find(|&b| y[b] >= lo)
            .unwrap_or(b_min_before);
        let end = (start..=b_max).find(|&b| y[b] >= hi).unwrap_or(b_max);
        (Phase::Growing, start..end.max(start + 1), rise)
    } else {
        let m = to_np(opts.floor_margin_db).min(fall / 3.0);
        let hi = y[b_max] - m;
        let lo = y[b_min_after] + m;
        let start = (b_max..=b_min_after).find(|&b| y[b] <= hi).unwrap_or(b_max);
        let end = (start..=b_min_after)
            .find(|&b| y[b] <= lo)
            .unwrap_or(b_min_after);
        (Phase::Decaying, start..end.max(start + 1), fall)
    };
    let mut window = i0 + blocks.start * bs..i0 + blocks.end * bs;
    if window.len() < 3 {
        window = i0..i0 + nb * bs; // very short records: fall back to the trimmed record
    }
    let mut fit = fit_growth_rate(&env, fs, window.clone())?;
    if phase != Phase::Flat {
        fit = refine(&centred, fs, window, fit.rate)?;
    }
    Ok(GrowthEstimate {
        phase,
        fit,
        total_change_db: change * DB_PER_NEPER,
    })
}

/// Second pass of [`growth_rate_linear_part`]: the first-pass envelope of a strongly growing
/// (decaying) record is biased at its small end by Hilbert leakage from its large end. Here the
/// window (padded by a fifth of its length on each side, within the record) is first flattened
/// by `e^{−σ₁(t−t_c)}` with the first-pass rate `σ₁`, so its amplitude is nearly uniform and
/// the end effects are small and confined to the padding; its envelope is then multiplied
/// back by `e^{σ₁(t−t_c)}` and refitted over the window.
fn refine(centred: &[f64], fs: f64, window: Range<usize>, rate1: f64) -> Result<GrowthFit> {
    let pad = window.len() / 5;
    let s0 = window.start.saturating_sub(pad);
    let s1 = (window.end + pad).min(centred.len());
    let c = 0.5 * (window.start + window.end) as f64;
    let tilt = |i: usize| (rate1 * (i as f64 - c) / fs).exp();
    let flat: Vec<f64> = (s0..s1).map(|i| centred[i] / tilt(i)).collect();
    let env = hilbert_envelope(&flat)?;
    let peak = env.iter().copied().fold(0.0, f64::max);
    let floor = peak * 1e-15;
    let env: Vec<f64> = env
        .iter()
        .enumerate()
        .map(|(j, e)| e.max(floor) * tilt(s0 + j))
        .collect();
    let mut fit = fit_growth_rate(&env, fs, window.start - s0..window.end - s0)?;
    let shift = s0 as f64 / fs;
    fit.t_start += shift;
    fit.t_end += shift;
    fit.ln_amp0 -= fit.rate * shift;
    Ok(fit)
}

fn validate(o: &GrowthOptions) -> Result<()> {
    if !(o.edge_fraction.is_finite() && (0.0..0.45).contains(&o.edge_fraction)) {
        return Err(invalid("edge_fraction", "must be in [0, 0.45)"));
    }
    if o.blocks < 2 {
        return Err(invalid("blocks", "must be >= 2"));
    }
    for (name, v) in [
        ("saturation_margin_db", o.saturation_margin_db),
        ("floor_margin_db", o.floor_margin_db),
        ("min_change_db", o.min_change_db),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(invalid(name, format!("must be finite and >= 0, got {v}")));
        }
    }
    Ok(())
}

/// Median of `x` (mean of the two middle values for even length); `x` must be non-empty.
pub(crate) fn median(x: &[f64]) -> f64 {
    let mut v = x.to_vec();
    let mid = v.len() / 2;
    let (_, &mut hi, _) = v.select_nth_unstable_by(mid, f64::total_cmp);
    if v.len() % 2 == 1 {
        hi
    } else {
        let lo = v[..mid].iter().copied().fold(f64::NEG_INFINITY, f64::max);
        0.5 * (lo + hi)
    }
}

fn argmax(y: &[f64]) -> usize {
    (0..y.len()).fold(0, |best, i| if y[i] > y[best] { i } else { best })
}

fn argmin(y: &[f64]) -> usize {
    (0..y.len()).fold(0, |best, i| if y[i] < y[best] { i } else { best })
}

#[cfg(test)]
mod tests {
    use super::median;

    #[test]
    fn median_odd_even() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), 2.5);
        assert_eq!(median(&[7.0]), 7.0);
    }
}
