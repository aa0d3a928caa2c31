//! Signal analysis for `squeal`: spectra, peaks, spectrograms, envelopes, growth rates,
//! run verdicts and band-limited audio rendering of simulated disc-brake vibration.
//!
//! Pure computation: no file I/O, no threads. Every fallible function validates its input
//! and returns a typed [`SignalError`] (empty signal, segment longer than the signal,
//! non-positive rate, NaN, …) instead of panicking.
//!
//! | module | provides |
//! | --- | --- |
//! | [`window`] | Hann, flat-top, rectangular windows ([`Window`]) |
//! | [`spectrum`] | Welch PSD ([`welch`]) and amplitude spectrum ([`amplitude_spectrum`]) |
//! | [`peaks`] | interpolated spectral peaks ([`find_peaks`]) |
//! | [`spectrogram`](mod@spectrogram) | short-time PSD ([`spectrogram()`]) |
//! | [`envelope`] | FFT Hilbert transform and envelope ([`hilbert_envelope`]) |
//! | [`growth`] | exponential growth/decay rates ([`fit_growth_rate`], [`growth_rate_linear_part`]) |
//! | [`line`](mod@line) | one line's frequency over a stretch, with its uncertainty ([`LineSpectrum`]) |
//! | [`metrics`] | RMS, dominant frequency, [`Verdict`] ([`classify`]) |
//! | [`radiation`] | equivalent radiated power, sound pressure, A-weighting ([`Listener`]) |
//! | [`verdict`] | the verdict of a whole run and its squeal answer ([`judge`]) |
//! | [`audio`] | Kaiser-sinc resampling and audio clips ([`render_audio`]) |
//!
//! ```
//! use squeal_signal::{find_peaks, growth_rate_linear_part, welch, GrowthOptions, PeakOptions,
//!     WelchOptions};
//! let fs = 200_000.0;
//! // a 5 kHz mode growing at σ = 12.5 1/s for 0.5 s
//! let x: Vec<f64> = (0..100_000)
//!     .map(|i| {
//!         let t = i as f64 / fs;
//!         (12.5 * t).exp() * (std::f64::consts::TAU * 5000.0 * t).sin()
//!     })
//!     .collect();
//! let psd = welch(&x, fs, &WelchOptions::default())?;
//! let peak = find_peaks(&psd, 1, &PeakOptions::default())[0];
//! assert!((peak.freq - 5000.0).abs() < 0.1 * psd.df);
//! let growth = growth_rate_linear_part(&x, fs, &GrowthOptions::default())?;
//! assert!((growth.fit.rate - 12.5).abs() < 0.125);
//! # Ok::<(), squeal_signal::SignalError>(())
//! ```

pub mod audio;
pub mod envelope;
pub mod error;
pub mod growth;
pub mod line;
pub mod metrics;
pub mod peaks;
pub mod radiation;
pub mod spectrogram;
pub mod spectrum;
pub mod verdict;
pub mod window;

pub use audio::{render_audio, resample, AudioClip, AudioOptions, ResampleOptions};
pub use envelope::{analytic_signal, hilbert_envelope, hilbert_transform};
pub use error::{Result, SignalError};
pub use growth::{
    fit_growth_rate, growth_rate_linear_part, GrowthEstimate, GrowthFit, GrowthOptions, Phase,
    DB_PER_NEPER,
};
pub use line::{Line, LineSpectrum};
pub use metrics::{
    classify, classify_with, dominant_frequency, rms, rms_tail, Classification, Verdict,
    VerdictOptions,
};
pub use peaks::{find_peaks, parabolic_vertex, window_response, Peak, PeakOptions};
pub use radiation::{a_weighting_db, mean_squares, Levels, Listener, Space};
pub use spectrogram::{spectrogram, Spectrogram};
pub use spectrum::{
    amplitude_spectrum, power_to_db, welch, Scaling, Spectrum, WelchOptions, DB_FLOOR,
};
pub use verdict::{
    gaps, judge, ContactRegime, Coordinate, CycleEvents, EventClass, JudgeError, JudgeOptions,
    Judgement, RunEvent, RunRecord, RunVerdict, Squeal, Trend,
};
pub use window::Window;

/// Complex number type used by [`analytic_signal`] (re-exported from `num-complex`).
pub use realfft::num_complex::Complex;
