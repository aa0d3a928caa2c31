//! Spectral-analysis windows.
//!
//! Written by hand because the three windows are a few lines each (sums of cosines) and no
//! crate in the workspace provides them; pulling in a DSP framework for them is not worth it.
//!
//! All windows are *periodic* (DFT-even): `w[n]` is evaluated on `n / N` rather than
//! `n / (N - 1)`, which is the correct form for FFT analysis (Harris, "On the use of windows
//! for harmonic analysis with the discrete Fourier transform", Proc. IEEE 66(1), 1978;
//! the same convention as `scipy.signal.get_window(..., fftbins=True)`).

use std::fmt;
use std::str::FromStr;

use crate::error::SignalError;

/// Flat-top window coefficients `a0..a4` (as in `scipy.signal.windows.flattop` and MATLAB
/// `flattopwin`; D'Antona & Ferrero, "Digital Signal Processing for Measurement Systems", 2006).
const FLATTOP: [f64; 5] = [
    0.215_578_95,
    0.416_631_58,
    0.277_263_158,
    0.083_578_947,
    0.006_947_368,
];

/// A spectral-analysis window.
///
/// Parsed from / printed as `"hann"`, `"flattop"`, `"rect"` for command-line use
/// (parsing also accepts `"hanning"`, `"flat-top"`, `"rectangular"`, `"boxcar"`,
/// case-insensitively).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Window {
    /// Hann window `w[n] = 0.5 − 0.5·cos(2πn/N)`: good frequency resolution, −31 dB first
    /// sidelobe, up to 1.42 dB scalloping loss (use peak interpolation for levels).
    #[default]
    Hann,
    /// Five-term flat-top window `w[n] = Σₖ (−1)ᵏ aₖ cos(2πkn/N)` (coefficients of
    /// MATLAB `flattopwin`): wide main lobe (±5 bins) but < 0.01 dB scalloping loss, so the
    /// amplitude of a sinusoid is read directly from the highest bin.
    FlatTop,
    /// Rectangular (boxcar) window `w[n] = 1`.
    Rect,
}

impl Window {
    /// All windows, in the order of their CLI names.
    pub const ALL: [Window; 3] = [Window::Hann, Window::FlatTop, Window::Rect];

    /// The CLI name: `"hann"`, `"flattop"` or `"rect"`.
    pub fn name(self) -> &'static str {
        match self {
            Window::Hann => "hann",
            Window::FlatTop => "flattop",
            Window::Rect => "rect",
        }
    }

    /// The periodic window of length `n` (formulas in the variant docs; `n = 1` gives `[1.0]`
    /// for every window, `n = 0` an empty vector).
    pub fn coefficients(self, n: usize) -> Vec<f64> {
        if n <= 1 {
            return vec![1.0; n];
        }
        let step = std::f64::consts::TAU / n as f64;
        (0..n)
            .map(|i| {
                let phi = step * i as f64;
                match self {
                    Window::Hann => 0.5 - 0.5 * phi.cos(),
                    Window::FlatTop => FLATTOP
                        .iter()
                        .enumerate()
                        .map(|(k, a)| {
                            let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
                            sign * a * (k as f64 * phi).cos()
                        })
                        .sum(),
                    Window::Rect => 1.0,
                }
            })
            .collect()
    }
}

impl fmt::Display for Window {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Window {
    type Err = SignalError;

    /// Parses a window name (case-insensitive; see [`Window`] for the accepted names).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "hann" | "hanning" => Ok(Window::Hann),
            "flattop" | "flat-top" | "flat_top" => Ok(Window::FlatTop),
            "rect" | "rectangular" | "boxcar" | "none" => Ok(Window::Rect),
            _ => Err(SignalError::UnknownWindow(s.to_string())),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for w in Window::ALL {
            assert_eq!(w.name().parse::<Window>().unwrap(), w);
            assert_eq!(w.to_string(), w.name());
        }
        assert_eq!("Flat-Top".parse::<Window>().unwrap(), Window::FlatTop);
        assert!(matches!(
            "kaiser".parse::<Window>(),
            Err(SignalError::UnknownWindow(_))
        ));
    }

    #[test]
    fn periodic_window_sums() {
        // Periodic Hann of even length: sum = N/2 exactly, sum of squares = 3N/8.
        let n = 1000;
        let w = Window::Hann.coefficients(n);
        let s: f64 = w.iter().sum();
        let s2: f64 = w.iter().map(|v| v * v).sum();
        assert!((s - 500.0).abs() < 1e-9, "sum {s}");
        assert!((s2 - 375.0).abs() < 1e-9, "sum sq {s2}");
        assert_eq!(w[0], 0.0);
        assert!((w[n / 2] - 1.0).abs() < 1e-15);
        // Flat-top: coherent gain a0 (mean of the window) and peak ≈ 1.
        let f = Window::FlatTop.coefficients(n);
        let mean: f64 = f.iter().sum::<f64>() / n as f64;
        assert!((mean - FLATTOP[0]).abs() < 1e-12, "mean {mean}");
        assert!((f[n / 2] - 1.0).abs() < 1e-8);
        assert_eq!(Window::Rect.coefficients(3), vec![1.0; 3]);
        assert_eq!(Window::Hann.coefficients(1), vec![1.0]);
        assert!(Window::Hann.coefficients(0).is_empty());
    }
}
