//! Welch-averaged power spectral density and amplitude spectra.
//!
//! Welch averaging is written by hand on top of `realfft` because no crate in the workspace
//! provides it; the FFT itself is `realfft` (planned once per call, buffers reused across
//! segments).
//!
//! Reference: P. D. Welch, "The use of fast Fourier transform for the estimation of power
//! spectra", IEEE Trans. Audio Electroacoust. 15(2), 1967; scaling as in
//! `scipy.signal.welch(..., scaling="density" | "spectrum")`.

use std::sync::Arc;

use realfft::num_complex::Complex;
use realfft::{RealFftPlanner, RealToComplex};

use crate::error::{check_rate, check_signal, invalid, Result, SignalError};
use crate::window::Window;

/// Floor of every dB conversion in the crate, in dB (10·log10 of 1e-30).
///
/// Values at or below `10^(DB_FLOOR/10)` (including exact zeros) map to `DB_FLOOR`, so dB
/// vectors never hold `-inf` or NaN.
pub const DB_FLOOR: f64 = -300.0;

/// Default Welch segment length in samples (used when the signal is at least this long).
pub const DEFAULT_SEG_LEN: usize = 8192;

/// `10·log10(p)` for a power-like quantity, floored at [`DB_FLOOR`] (NaN and `p ≤ 0` also
/// map to the floor).
pub fn power_to_db(p: f64) -> f64 {
    let floor = 10f64.powf(DB_FLOOR / 10.0);
    if p > floor {
        10.0 * p.log10()
    } else {
        DB_FLOOR
    }
}

/// Options of [`welch`] and [`amplitude_spectrum`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WelchOptions {
    /// Segment (FFT) length in samples; `None` means `min(DEFAULT_SEG_LEN, signal length)`.
    /// Any length ≥ 2 works (powers of two are not required). Frequency resolution is
    /// `df = fs / seg_len`.
    pub seg_len: Option<usize>,
    /// Fraction of a segment shared with the next one, in `[0, 1)`; default 0.5.
    /// The hop is `max(1, round(seg_len·(1 − overlap)))`.
    pub overlap: f64,
    /// Window applied to every segment; default [`Window::Hann`].
    pub window: Window,
    /// Subtract each segment's mean before windowing (default `true`), so DC does not leak
    /// into the low bins.
    pub remove_mean: bool,
}

impl Default for WelchOptions {
    fn default() -> Self {
        Self {
            seg_len: None,
            overlap: 0.5,
            window: Window::Hann,
            remove_mean: true,
        }
    }
}

/// What the values of a [`Spectrum`] mean.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scaling {
    /// One-sided power spectral density in units²/Hz: `Σ psd·df` ≈ variance (Parseval).
    Density,
    /// Squared *peak* amplitude of a sinusoid in units²: a component `A·cos(2πft)` gives
    /// `A²` at its bin (exactly so on-bin, or with a flat-top window). `to_db()` therefore
    /// reads `20·log10(A)`; [`Spectrum::amplitude`] returns `A`.
    Amplitude,
}

/// A one-sided spectrum on the bins `freq[k] = k·df`, `k = 0 ..= seg_len/2`.
#[derive(Debug, Clone, PartialEq)]
pub struct Spectrum {
    /// Bin frequencies in Hz, `k·df`.
    pub freq: Vec<f64>,
    /// Spectral values; meaning given by [`Spectrum::scaling`] (units²/Hz for the PSD of
    /// [`welch`], squared peak amplitude for [`amplitude_spectrum`]).
    pub psd: Vec<f64>,
    /// Bin spacing `fs / seg_len` in Hz.
    pub df: f64,
    /// Meaning of `psd`.
    pub scaling: Scaling,
    /// Number of segments averaged.
    pub segments: usize,
    /// Window the segments were multiplied by (peak interpolation depends on it).
    pub window: Window,
}

impl Spectrum {
    /// Number of bins.
    pub fn len(&self) -> usize {
        self.psd.len()
    }

    /// `true` if there are no bins (never the case for spectra made by this crate).
    pub fn is_empty(&self) -> bool {
        self.psd.is_empty()
    }

    /// `10·log10(psd)` per bin, floored at [`DB_FLOOR`] (never `-inf` or NaN).
    /// For [`Scaling::Amplitude`] this is `20·log10(A)`, dB re 1 unit peak.
    pub fn to_db(&self) -> Vec<f64> {
        self.psd.iter().map(|&p| power_to_db(p)).collect()
    }

    /// `sqrt(psd)` per bin: the peak amplitude for [`Scaling::Amplitude`], the amplitude
    /// spectral density (units/√Hz) for [`Scaling::Density`].
    pub fn amplitude(&self) -> Vec<f64> {
        self.psd.iter().map(|p| p.max(0.0).sqrt()).collect()
    }

    /// Rectangle-rule integral `Σ psd[k]·df` over all bins. For [`Scaling::Density`] this is
    /// the variance (mean-square after mean removal) of the signal, by Parseval's theorem.
    pub fn total_power(&self) -> f64 {
        self.psd.iter().sum::<f64>() * self.df
    }

    /// `Σ psd[k]·df` over the bins with `f_lo ≤ freq[k] ≤ f_hi` (band power for a density).
    pub fn band_power(&self, f_lo: f64, f_hi: f64) -> f64 {
        self.freq
            .iter()
            .zip(&self.psd)
            .filter(|(f, _)| **f >= f_lo && **f <= f_hi)
            .map(|(_, p)| p)
            .sum::<f64>()
            * self.df
    }

    /// Index of the bin nearest to `f` Hz (clamped to the valid range).
    pub fn bin_of(&self, f: f64) -> usize {
        let k = (f / self.df).round();
        if k.is_nan() || k <= 0.0 {
            0
        } else {
            (k as usize).min(self.len().saturating_sub(1))
        }
    }
}

/// One windowed real FFT frame: plan, window and buffers allocated once and reused for every
/// segment of a call.
pub(crate) struct FrameFft {
    r2c: Arc<dyn RealToComplex<f64>>,
    input: Vec<f64>,
    output: Vec<Complex<f64>>,
    scratch: Vec<Complex<f64>>,
    window: Vec<f64>,
}

impl FrameFft {
    pub(crate) fn new(seg_len: usize, window: Window) -> Self {
        let mut planner = RealFftPlanner::<f64>::new();
        let r2c = planner.plan_fft_forward(seg_len);
        Self {
            input: r2c.make_input_vec(),
            output: r2c.make_output_vec(),
            scratch: r2c.make_scratch_vec(),
            window: window.coefficients(seg_len),
            r2c,
        }
    }

    /// `Σ w[n]`.
    pub(crate) fn window_sum(&self) -> f64 {
        self.window.iter().sum()
    }

    /// `Σ w[n]²`.
    pub(crate) fn window_sum_sq(&self) -> f64 {
        self.window.iter().map(|w| w * w).sum()
    }

    /// Transforms `frame` (mean removed if asked, then windowed) and adds `|X[k]|²` to `acc`.
    pub(crate) fn accumulate_power(
        &mut self,
        frame: &[f64],
        remove_mean: bool,
        acc: &mut [f64],
    ) -> Result<()> {
        let mean = if remove_mean {
            frame.iter().sum::<f64>() / frame.len() as f64
        } else {
            0.0
        };
        for ((dst, &v), &w) in self.input.iter_mut().zip(frame).zip(&self.window) {
            *dst = (v - mean) * w;
        }
        self.r2c
            .process_with_scratch(&mut self.input, &mut self.output, &mut self.scratch)?;
        for (a, c) in acc.iter_mut().zip(&self.output) {
            *a += c.norm_sqr();
        }
        Ok(())
    }
}

/// Validated segmentation of a signal: segment length, hop and number of segments.
pub(crate) fn segmentation(n: usize, opts: &WelchOptions) -> Result<(usize, usize, usize)> {
    if n < 2 {
        return Err(SignalError::TooShort { need: 2, got: n });
    }
    let seg_len = opts.seg_len.unwrap_or(DEFAULT_SEG_LEN.min(n));
    if seg_len < 2 {
        return Err(invalid("seg_len", format!("must be >= 2, got {seg_len}")));
    }
    if seg_len > n {
        return Err(SignalError::SegmentTooLong { seg_len, len: n });
    }
    if !(opts.overlap.is_finite() && (0.0..1.0).contains(&opts.overlap)) {
        return Err(invalid(
            "overlap",
            format!("must be in [0, 1), got {}", opts.overlap),
        ));
    }
    let hop = ((seg_len as f64 * (1.0 - opts.overlap)).round() as usize).max(1);
    let segments = (n - seg_len) / hop + 1;
    Ok((seg_len, hop, segments))
}

/// Average of `|X[k]|²` over the Welch segments, plus the frame (for window sums).
fn welch_mean_power(
    x: &[f64],
    fs: f64,
    opts: &WelchOptions,
) -> Result<(Vec<f64>, FrameFft, usize, usize)> {
    check_signal(x)?;
    check_rate(fs)?;
    let (seg_len, hop, segments) = segmentation(x.len(), opts)?;
    let mut frame = FrameFft::new(seg_len, opts.window);
    let mut acc = vec![0.0; seg_len / 2 + 1];
    for s in 0..segments {
        let start = s * hop;
        frame.accumulate_power(&x[start..start + seg_len], opts.remove_mean, &mut acc)?;
    }
    let inv = 1.0 / segments as f64;
    acc.iter_mut().for_each(|a| *a *= inv);
    Ok((acc, frame, seg_len, segments))
}

/// `true` for the bins that appear twice in a two-sided spectrum (all but DC and, for even
/// `seg_len`, Nyquist).
pub(crate) fn is_doubled(k: usize, seg_len: usize) -> bool {
    k != 0 && !(seg_len % 2 == 0 && k == seg_len / 2)
}

/// Welch power spectral density, one-sided, in units²/Hz.
///
/// The signal is cut into segments of `seg_len` samples with the given overlap; each is
/// (optionally) mean-removed, multiplied by the window `w` and transformed. The estimate is
///
/// `P[k] = c_k · mean_segments |X[k]|² / (fs · Σ w[n]²)`, with `c_k = 2` except `c_0 = 1` and
/// `c_{N/2} = 1` (Nyquist, even `N`),
///
/// so that `Σ P[k]·df ≈ variance` (Parseval). Trailing samples that do not fill a whole
/// segment are not used (as in `scipy.signal.welch`).
///
/// Errors: empty signal, NaN/inf samples, `fs ≤ 0`, `seg_len < 2`, `seg_len` longer than the
/// signal, `overlap` outside `[0, 1)`.
pub fn welch(x: &[f64], fs: f64, opts: &WelchOptions) -> Result<Spectrum> {
    let (mut p, frame, seg_len, segments) = welch_mean_power(x, fs, opts)?;
    let scale = 1.0 / (fs * frame.window_sum_sq());
    for (k, v) in p.iter_mut().enumerate() {
        *v *= if is_doubled(k, seg_len) {
            2.0 * scale
        } else {
            scale
        };
    }
    Ok(finish(
        p,
        fs,
        seg_len,
        Scaling::Density,
        segments,
        opts.window,
    ))
}

/// Welch-averaged amplitude spectrum: squared peak amplitude of sinusoidal components.
///
/// `A²[k] = c_k · mean_segments |X[k]|² / (Σ w[n])²` with `c_k = 4` except `c_0 = 1` and
/// `c_{N/2} = 1`. A sinusoid `A·cos(2πf₀t)` far from DC gives `|X| = A·Σw/2` at an on-bin
/// `f₀`, hence `A²` (see [`Scaling::Amplitude`]). Off-bin, the Hann window loses up to
/// 1.42 dB (recover it with [`crate::find_peaks`]' interpolation); the flat-top window loses
/// < 0.01 dB and gives accurate levels directly.
///
/// Same options and errors as [`welch`].
pub fn amplitude_spectrum(x: &[f64], fs: f64, opts: &WelchOptions) -> Result<Spectrum> {
    let (mut p, frame, seg_len, segments) = welch_mean_power(x, fs, opts)?;
    let sw = frame.window_sum();
    let scale = 1.0 / (sw * sw);
    for (k, v) in p.iter_mut().enumerate() {
        *v *= if is_doubled(k, seg_len) {
            4.0 * scale
        } else {
            scale
        };
    }
    Ok(finish(
        p,
        fs,
        seg_len,
        Scaling::Amplitude,
        segments,
        opts.window,
    ))
}

fn finish(
    psd: Vec<f64>,
    fs: f64,
    seg_len: usize,
    scaling: Scaling,
    segments: usize,
    window: Window,
) -> Spectrum {
    let df = fs / seg_len as f64;
    Spectrum {
        freq: (0..psd.len()).map(|k| k as f64 * df).collect(),
        psd,
        df,
        scaling,
        segments,
        window,
    }
}
