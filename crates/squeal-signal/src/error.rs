//! Typed errors for every fallible operation in the crate.
//!
//! Every public function validates its input and returns one of these rather than panicking:
//! empty signals, segments longer than the signal, non-positive or non-finite rates and
//! non-finite samples are all reported here.

use thiserror::Error;

/// Error returned by the analysis functions of this crate when the input cannot be processed.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SignalError {
    /// The signal has no samples.
    #[error("signal is empty")]
    EmptySignal,
    /// The signal is shorter than the operation needs.
    #[error("signal too short: need at least {need} samples, got {got}")]
    TooShort {
        /// Minimum number of samples required.
        need: usize,
        /// Number of samples supplied.
        got: usize,
    },
    /// An analysis segment (FFT frame) is longer than the signal.
    #[error("segment length {seg_len} is longer than the signal ({len} samples)")]
    SegmentTooLong {
        /// Requested segment length in samples.
        seg_len: usize,
        /// Signal length in samples.
        len: usize,
    },
    /// A sample rate is zero, negative, NaN or infinite.
    #[error("sample rate must be finite and > 0, got {0}")]
    InvalidRate(f64),
    /// The signal contains NaN or an infinity.
    #[error("signal contains a non-finite value ({value}) at index {index}")]
    NonFinite {
        /// Index of the first offending sample.
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// A numerical parameter is out of its valid range.
    #[error("invalid parameter `{name}`: {reason}")]
    InvalidParameter {
        /// Name of the parameter (as in the options struct or argument list).
        name: &'static str,
        /// What is wrong with it.
        reason: String,
    },
    /// An envelope passed to a log-linear fit has a non-positive value, whose logarithm is
    /// undefined.
    #[error("envelope value {value} at index {index} is not > 0; cannot take its logarithm")]
    NonPositiveEnvelope {
        /// Index of the first offending sample.
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// A window name was not recognised (see [`crate::Window`]).
    #[error("unknown window `{0}` (expected one of: hann, flattop, rect)")]
    UnknownWindow(String),
    /// The FFT library reported an error (indicates a bug in buffer sizing, not bad input).
    #[error("FFT failed: {0}")]
    Fft(String),
}

/// Result alias used throughout the crate.
pub type Result<T> = std::result::Result<T, SignalError>;

impl From<realfft::FftError> for SignalError {
    fn from(e: realfft::FftError) -> Self {
        SignalError::Fft(e.to_string())
    }
}

/// Checks that `x` is non-empty and every sample is finite.
pub(crate) fn check_signal(x: &[f64]) -> Result<()> {
    if x.is_empty() {
        return Err(SignalError::EmptySignal);
    }
    if let Some((index, &value)) = x.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(SignalError::NonFinite { index, value });
    }
    Ok(())
}

/// Checks that a sample rate is finite and strictly positive.
pub(crate) fn check_rate(fs: f64) -> Result<()> {
    if fs.is_finite() && fs > 0.0 {
        Ok(())
    } else {
        Err(SignalError::InvalidRate(fs))
    }
}

/// Builds an [`SignalError::InvalidParameter`].
pub(crate) fn invalid(name: &'static str, reason: impl Into<String>) -> SignalError {
    SignalError::InvalidParameter {
        name,
        reason: reason.into(),
    }
}
