//! Audio rendering: band-limited resampling to an audio rate, looping, normalisation, fades.
//!
//! The resampler is written by hand because the workspace has no resampling crate and the
//! requirement is specific: an arbitrary (also non-rational) rate ratio, true pitch, and a
//! guaranteed stop band so that 20–35 kHz content of a 200 kHz simulation cannot alias into
//! the audible band. Writing the WAV file is left to the caller.

use crate::error::{check_rate, check_signal, invalid, Result};

/// Table points per input sample for the tabulated resampling kernel (linear interpolation
/// between them; the interpolation error is far below the stop-band level).
const KERNEL_OVERSAMPLING: usize = 512;

/// Largest kernel table (entries); for very wide kernels (extreme decimation, where the kernel
/// is correspondingly smooth) the oversampling is reduced to stay below it.
const MAX_TABLE: usize = 1 << 22;

/// Largest kernel half-width (input samples) and output length the resampler accepts.
const MAX_HALF_WIDTH: f64 = 1e8;
const MAX_OUTPUT: usize = 1 << 28;

/// Modified Bessel function of the first kind, order zero, `I₀(x) = Σₖ ((x/2)ᵏ/k!)²`
/// (power series, Abramowitz & Stegun 9.6.12), summed to full double precision.
pub fn bessel_i0(x: f64) -> f64 {
    let q = 0.25 * x * x;
    let (mut term, mut sum, mut k) = (1.0, 1.0, 1.0);
    while term > 1e-17 * sum {
        term *= q / (k * k);
        sum += term;
        k += 1.0;
    }
    sum
}

/// Kaiser window shape parameter `β` for a stop-band attenuation of `atten_db`
/// (Kaiser 1974; Oppenheim & Schafer, *Discrete-Time Signal Processing*, eq. 7.62):
/// `0.1102(A − 8.7)` for `A > 50`, `0.5842(A − 21)^0.4 + 0.07886(A − 21)` for
/// `21 ≤ A ≤ 50`, `0` below.
pub fn kaiser_beta(atten_db: f64) -> f64 {
    if atten_db > 50.0 {
        0.1102 * (atten_db - 8.7)
    } else if atten_db >= 21.0 {
        0.5842 * (atten_db - 21.0).powf(0.4) + 0.07886 * (atten_db - 21.0)
    } else {
        0.0
    }
}

/// Options of [`resample`]: the low-pass applied while changing rate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResampleOptions {
    /// Pass-band edge in Hz (default 20 000).
    pub passband_hz: f64,
    /// Stop-band edge in Hz (default 24 000).
    pub stopband_hz: f64,
    /// Design stop-band attenuation in dB (default 90, range 21–200).
    pub attenuation_db: f64,
}

impl Default for ResampleOptions {
    fn default() -> Self {
        Self {
            passband_hz: 20_000.0,
            stopband_hz: 24_000.0,
            attenuation_db: 90.0,
        }
    }
}

/// A designed Kaiser-windowed-sinc kernel, tabulated in input-sample units.
struct Kernel {
    /// `g(u)` for `u = j / oversampling`, `u ∈ [0, half_width]`, then zeros.
    table: Vec<f64>,
    /// Table points per input sample.
    oversampling: f64,
    /// Half-width in input samples.
    half_width: f64,
    /// Half-width in seconds.
    half_width_s: f64,
}

impl Kernel {
    /// Design for the given rates; see [`resample`] for the formulas.
    fn design(fs_in: f64, fs_out: f64, o: &ResampleOptions) -> Result<Self> {
        if !(o.passband_hz.is_finite() && o.passband_hz > 0.0) {
            return Err(invalid("passband_hz", "must be finite and > 0"));
        }
        if !(o.stopband_hz.is_finite() && o.stopband_hz > o.passband_hz) {
            return Err(invalid("stopband_hz", "must be finite and > passband_hz"));
        }
        if !(21.0..=200.0).contains(&o.attenuation_db) {
            return Err(invalid("attenuation_db", "must be in [21, 200]"));
        }
        let nyq = 0.5 * fs_in.min(fs_out);
        let scale = (nyq / o.stopband_hz).min(1.0);
        let (pass, stop) = (o.passband_hz * scale, o.stopband_hz * scale);
        let fc = 0.5 * (pass + stop);
        let half_width_s =
            (o.attenuation_db - 7.95) / (2.285 * std::f64::consts::TAU * (stop - pass)) / 2.0;
        let half_width = half_width_s * fs_in;
        let beta = kaiser_beta(o.attenuation_db);
        let i0b = bessel_i0(beta);
        let a = 2.0 * fc / fs_in; // sinc argument scale and DC normalisation
        if !(half_width.is_finite() && half_width <= MAX_HALF_WIDTH) {
            return Err(invalid(
                "fs_out",
                format!("rate ratio {fs_in}/{fs_out} too extreme (kernel {half_width} samples)"),
            ));
        }
        let oversampling =
            ((MAX_TABLE as f64 / half_width).floor() as usize).clamp(1, KERNEL_OVERSAMPLING) as f64;
        let npts = (half_width * oversampling).ceil() as usize + 2;
        let table = (0..npts)
            .map(|j| {
                let u = j as f64 / oversampling;
                let r = u / half_width;
                if r >= 1.0 {
                    return 0.0;
                }
                let arg = std::f64::consts::PI * a * u;
                let sinc = if arg == 0.0 { 1.0 } else { arg.sin() / arg };
                a * sinc * bessel_i0(beta * (1.0 - r * r).sqrt()) / i0b
            })
            .collect();
        Ok(Self {
            table,
            oversampling,
            half_width,
            half_width_s,
        })
    }

    #[inline]
    fn eval(&self, d: f64) -> f64 {
        let pos = d.abs() * self.oversampling;
        let j = pos as usize;
        match (self.table.get(j), self.table.get(j + 1)) {
            (Some(&g0), Some(&g1)) => {
                let f = pos - j as f64;
                g0 + (g1 - g0) * f
            }
            _ => 0.0,
        }
    }
}

/// Band-limited resampling from `fs_in` to `fs_out` (any ratio, up or down) by direct
/// evaluation of the Whittaker–Shannon sum with a Kaiser-windowed sinc:
///
/// `y[m] = Σₙ x[n]·g(m·fs_in/fs_out − n)`,
/// `g(u) = a·sinc(a·u)·I₀(β√(1 − (u/K)²))/I₀(β)` for `|u| < K`, `a = 2f_c/fs_in`,
///
/// with `f_c` midway between the pass- and stop-band edges, `β` from [`kaiser_beta`] and the
/// half-width `K = fs_in·(A − 7.95)/(2·2.285·2π·Δf)` samples from Kaiser's length formula
/// (`Δf` = transition width). When `min(fs_in, fs_out)/2` is below the requested stop-band
/// edge, both edges are scaled down in proportion so the stop band starts at that Nyquist
/// frequency (anti-aliasing when decimating, anti-imaging when interpolating). Samples outside
/// the record count as zero. The output covers the same time span: `floor((N−1)·fs_out/fs_in) + 1`
/// samples.
///
/// Errors: empty/non-finite signal, a rate `≤ 0`, invalid options, a rate ratio so extreme
/// that the kernel would exceed 10⁸ input samples or the output 2²⁸ samples.
pub fn resample(x: &[f64], fs_in: f64, fs_out: f64, opts: &ResampleOptions) -> Result<Vec<f64>> {
    check_signal(x)?;
    check_rate(fs_in)?;
    check_rate(fs_out)?;
    let kernel = Kernel::design(fs_in, fs_out, opts)?;
    check_output_len(x.len(), fs_in, fs_out)?;
    Ok(resample_with(x, fs_in, fs_out, &kernel))
}

fn check_output_len(n: usize, fs_in: f64, fs_out: f64) -> Result<()> {
    let out = (n - 1) as f64 * fs_out / fs_in + 1.0;
    if out > MAX_OUTPUT as f64 {
        return Err(invalid(
            "fs_out",
            format!("output would have {out:.3e} samples (limit {MAX_OUTPUT})"),
        ));
    }
    Ok(())
}

fn resample_with(x: &[f64], fs_in: f64, fs_out: f64, k: &Kernel) -> Vec<f64> {
    let n = x.len();
    let ratio = fs_in / fs_out;
    let out_len = ((n - 1) as f64 / ratio).floor() as usize + 1;
    (0..out_len)
        .map(|m| {
            let c = m as f64 * ratio;
            let lo = (c - k.half_width).ceil().max(0.0) as usize;
            let hi = ((c + k.half_width).floor() as usize).min(n - 1);
            (lo..=hi).map(|i| x[i] * k.eval(c - i as f64)).sum()
        })
        .collect()
}

/// Options of [`render_audio`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AudioOptions {
    /// Output sample rate in Hz (default 48 000).
    pub sample_rate: u32,
    /// Minimum clip length in seconds (default 2.0); shorter input is looped.
    pub min_seconds: f64,
    /// Peak level after normalisation, as a fraction of full scale, in `(0, 1]` (default 0.9).
    pub peak: f64,
    /// Raised-cosine fade-in and fade-out length in seconds (default 0.01).
    pub fade_seconds: f64,
    /// Linear crossfade at each loop splice, in seconds (default 0.005).
    pub crossfade_seconds: f64,
    /// Fraction at the end of the (resampled) signal that is looped, in `(0, 1]`
    /// (default 0.5: the last half, taken to be the steady part).
    pub loop_fraction: f64,
    /// Anti-aliasing low-pass of the resampler.
    pub resampler: ResampleOptions,
    /// A fixed level reference instead of normalisation: the signal value (in its
    /// own units, e.g. m/s) rendered at full scale (sample value 1) before
    /// `gain_db`. `None` (default): normalise to `peak`.
    pub full_scale: Option<f64>,
    /// Gain in dB applied on top of the `full_scale` reference (default 0).
    pub gain_db: f64,
    /// Transposition in octaves (default 0: true pitch). `−2` plays the signal
    /// two octaves lower: it is resampled as if recorded at `fs_in·2^t`, and the
    /// clip keeps the duration it would have at true pitch (its last part).
    pub transpose_octaves: f64,
}

impl Default for AudioOptions {
    fn default() -> Self {
        Self {
            sample_rate: 48_000,
            min_seconds: 2.0,
            peak: 0.9,
            fade_seconds: 0.01,
            crossfade_seconds: 0.005,
            loop_fraction: 0.5,
            resampler: ResampleOptions::default(),
            full_scale: None,
            gain_db: 0.0,
            transpose_octaves: 0.0,
        }
    }
}

/// A rendered mono clip, ready to be written as a WAV file.
#[derive(Debug, Clone, PartialEq)]
pub struct AudioClip {
    /// Samples in `[-1, 1]` (full scale = 1).
    pub samples: Vec<f32>,
    /// Sample rate in Hz.
    pub sample_rate: u32,
    /// `true` if the input was shorter than `min_seconds` and its last part was looped.
    pub looped: bool,
    /// Duration of the input signal in seconds (`N / fs_in`).
    pub source_seconds: f64,
    /// Gain applied (`peak / max|y|` when normalising, 0 for a silent input;
    /// `10^(gain_db/20) / full_scale` with a fixed reference).
    pub gain: f64,
    /// Samples beyond full scale, clipped to ±1 (only with a fixed reference).
    pub clipped: usize,
    /// RMS of the clip in dB re full scale (a constant at full scale is 0 dB;
    /// a full-scale sine −3.01 dB); −inf for silence.
    pub rms_dbfs: f64,
}

impl AudioClip {
    /// Clip duration in seconds.
    pub fn duration(&self) -> f64 {
        self.samples.len() as f64 / self.sample_rate as f64
    }
}

/// Renders a simulated signal `x` (rate `fs_in`) as audio at true pitch.
///
/// Steps: remove the mean; [`resample`] to `sample_rate` with the `resampler` low-pass
/// (default: pass band 20 kHz, stop band from 24 kHz, 90 dB); if shorter than `min_seconds`,
/// loop its last `loop_fraction`, spliced between rising zero crossings (start of the loop
/// and splice point) with a `crossfade_seconds` linear crossfade from the signal's own
/// continuation into the loop start, and set `looped`; apply raised-cosine fades
/// (`w = sin²(π/2·(i+½)/L)`) of `fade_seconds` at both ends; normalise so that
/// `max|y| = peak`·full scale — or, with a fixed reference `full_scale`, multiply by
/// `10^(gain_db/20)/full_scale` (no normalisation: louder input is louder output; samples
/// beyond full scale are clipped and counted); convert to `f32`. An identically constant
/// input gives silence (all zeros, gain 0 when normalising). With `transpose_octaves = t`
/// the input is resampled as if recorded at `fs_in·2^t` (every frequency × 2^t) and the
/// last part of the result of the true-pitch duration is kept.
///
/// Errors: empty/non-finite signal, `fs_in ≤ 0`, invalid options (including more than 2²⁸
/// output samples).
pub fn render_audio(x: &[f64], fs_in: f64, opts: &AudioOptions) -> Result<AudioClip> {
    check_signal(x)?;
    check_rate(fs_in)?;
    validate(opts)?;
    let rate = opts.sample_rate as f64;
    let kernel = Kernel::design(fs_in, rate, &opts.resampler)?;
    check_output_len(x.len(), fs_in, rate)?;
    let mean = x.iter().sum::<f64>() / x.len() as f64;
    let centred: Vec<f64> = x.iter().map(|v| v - mean).collect();
    // Transposed: the same samples read at fs_in·2^t (a proper band-limited
    // resampling to the audio rate, not a faster or slower playback of it);
    // the clip keeps the true-pitch duration, taking the last part.
    let fs_eff = fs_in * 2f64.powf(opts.transpose_octaves);
    let y = if opts.transpose_octaves != 0.0 {
        let kernel_t = Kernel::design(fs_eff, rate, &opts.resampler)?;
        check_output_len(x.len(), fs_eff, rate)?;
        let y = resample_with(&centred, fs_eff, rate, &kernel_t);
        let keep = ((x.len() as f64 / fs_in * rate).round() as usize).clamp(1, y.len());
        y[y.len() - keep..].to_vec()
    } else {
        resample_with(&centred, fs_in, rate, &kernel)
    };

    let min_len = (opts.min_seconds * rate).ceil() as usize;
    let looped = y.len() < min_len;
    let mut out = if looped {
        let guard = (kernel.half_width_s * rate).ceil() as usize + 1;
        let cf = (opts.crossfade_seconds * rate).round() as usize;
        loop_to_length(&y, min_len, opts.loop_fraction, guard, cf)
    } else {
        y
    };

    let fade = ((opts.fade_seconds * rate).round() as usize).min(out.len() / 2);
    let len = out.len();
    for i in 0..fade {
        let w = (std::f64::consts::FRAC_PI_2 * (i as f64 + 0.5) / fade as f64)
            .sin()
            .powi(2);
        out[i] *= w;
        out[len - 1 - i] *= w;
    }
    let peak = out.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let gain = match opts.full_scale {
        Some(fsv) => 10f64.powf(opts.gain_db / 20.0) / fsv,
        None if peak >= f64::MIN_POSITIVE => opts.peak / peak,
        None => 0.0,
    };
    out.iter_mut().for_each(|v| *v *= gain);
    let clipped = out.iter().filter(|v| v.abs() > 1.0).count();
    let ms = out.iter().map(|v| v.clamp(-1.0, 1.0).powi(2)).sum::<f64>() / out.len().max(1) as f64;
    Ok(AudioClip {
        samples: out.iter().map(|&v| (v as f32).clamp(-1.0, 1.0)).collect(),
        sample_rate: opts.sample_rate,
        looped,
        source_seconds: x.len() as f64 / fs_in,
        gain,
        clipped,
        rms_dbfs: 10.0 * ms.log10(),
    })
}

/// Index of each rising zero crossing `i` (`y[i−1] < 0 ≤ y[i]`) in `range`.
fn rising_crossings(y: &[f64], range: std::ops::Range<usize>) -> impl Iterator<Item = usize> + '_ {
    range.filter(move |&i| i > 0 && i < y.len() && y[i - 1] < 0.0 && y[i] >= 0.0)
}

/// Extends `y` to `target` samples by repeating `y[a..b]` after `y[..b]`, crossfading the
/// first `cf` samples of each repeat from `y[b..b+cf]` (the signal's continuation).
fn loop_to_length(y: &[f64], target: usize, fraction: f64, guard: usize, cf: usize) -> Vec<f64> {
    let len = y.len();
    let a_min = ((len as f64 * (1.0 - fraction)).floor() as usize).min(len.saturating_sub(1));
    let usable_end = if len > guard + a_min {
        len - guard
    } else {
        len
    };
    let (mut a, mut b, mut cf) = (a_min, usable_end.saturating_sub(cf), cf);
    if b > a + 2 * cf.max(1) {
        let b_zc = rising_crossings(y, a + 1..b + 1).last();
        let a_zc = rising_crossings(y, a..b).next();
        if let (Some(az), Some(bz)) = (a_zc, b_zc) {
            if bz > az + 2 * cf.max(1) {
                (a, b) = (az, bz);
            }
        }
    } else {
        // Too short to splice politely: loop the whole signal without a crossfade.
        (a, b, cf) = (0, len, 0);
    }
    let mut out = Vec::with_capacity(target + (b - a));
    out.extend_from_slice(&y[..b]);
    while out.len() < target {
        for i in 0..b - a {
            let v = if i < cf {
                let w = (i as f64 + 0.5) / cf as f64;
                (1.0 - w) * y[b + i] + w * y[a + i]
            } else {
                y[a + i]
            };
            out.push(v);
        }
    }
    out.truncate(target);
    out
}

fn validate(o: &AudioOptions) -> Result<()> {
    if o.sample_rate == 0 {
        return Err(invalid("sample_rate", "must be > 0"));
    }
    if !(o.min_seconds.is_finite()
        && o.min_seconds >= 0.0
        && o.min_seconds * o.sample_rate as f64 <= MAX_OUTPUT as f64)
    {
        return Err(invalid(
            "min_seconds",
            format!("must be >= 0 and give at most {MAX_OUTPUT} samples"),
        ));
    }
    if !(o.peak > 0.0 && o.peak <= 1.0) {
        return Err(invalid("peak", "must be in (0, 1]"));
    }
    for (name, v) in [
        ("fade_seconds", o.fade_seconds),
        ("crossfade_seconds", o.crossfade_seconds),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(invalid(name, format!("must be finite and >= 0, got {v}")));
        }
    }
    if !(o.loop_fraction > 0.0 && o.loop_fraction <= 1.0) {
        return Err(invalid("loop_fraction", "must be in (0, 1]"));
    }
    if let Some(f) = o.full_scale {
        if !(f.is_finite() && f > 0.0) {
            return Err(invalid(
                "full_scale",
                format!("must be finite and > 0, got {f}"),
            ));
        }
    }
    if !(o.gain_db.is_finite() && o.gain_db.abs() <= 200.0) {
        return Err(invalid(
            "gain_db",
            format!("must be within ±200 dB, got {}", o.gain_db),
        ));
    }
    if !(o.transpose_octaves.is_finite() && o.transpose_octaves.abs() <= 6.0) {
        return Err(invalid(
            "transpose_octaves",
            format!("must be within ±6 octaves, got {}", o.transpose_octaves),
        ));
    }
    Ok(())
}
