//! Analytic signal and envelope via the FFT Hilbert transform.
//!
//! Reference: S. L. Marple, "Computing the discrete-time analytic signal via FFT",
//! IEEE Trans. Signal Process. 47(9), 1999 (the method of `scipy.signal.hilbert`).
//! Built on `realfft` (one forward and one inverse real FFT).

use realfft::num_complex::Complex;
use realfft::RealFftPlanner;

use crate::error::{check_signal, Result};

/// Smallest `m ≥ n` whose only prime factors are 2, 3 and 5 (fast FFT sizes).
pub(crate) fn next_fast_len(n: usize) -> usize {
    let mut m = n.max(1);
    loop {
        let mut r = m;
        for p in [2, 3, 5] {
            while r % p == 0 {
                r /= p;
            }
        }
        if r == 1 {
            return m;
        }
        m += 1;
    }
}

/// Discrete Hilbert transform `H{x}` (same length as `x`).
///
/// `x` is zero-padded to an even 2·3·5-smooth length `M ≥ 2N`, transformed, multiplied by
/// `−i·sign(k)` (DC and Nyquist set to zero), and inverse transformed; the first `N`
/// samples are returned. The padding keeps the circular wrap-around of the FFT from coupling
/// the end of the record into its start (important for exponentially growing signals, whose
/// end is orders of magnitude larger than their start); the remaining end effects decay like
/// `1/(2π²·cycles)` away from each end of the record.
///
/// The mean is *not* removed: subtract it first if the signal has an offset.
///
/// Errors: empty signal, NaN/inf samples.
pub fn hilbert_transform(x: &[f64]) -> Result<Vec<f64>> {
    check_signal(x)?;
    let n = x.len();
    let m = 2 * next_fast_len(n);
    let mut planner = RealFftPlanner::<f64>::new();
    let fwd = planner.plan_fft_forward(m);
    let inv = planner.plan_fft_inverse(m);
    let mut buf = fwd.make_input_vec();
    buf[..n].copy_from_slice(x);
    let mut spec = fwd.make_output_vec();
    let mut scratch =
        vec![Complex::new(0.0, 0.0); fwd.get_scratch_len().max(inv.get_scratch_len())];
    fwd.process_with_scratch(&mut buf, &mut spec, &mut scratch)?;
    let last = spec.len() - 1; // Nyquist bin (m is even)
    spec[0] = Complex::new(0.0, 0.0);
    spec[last] = Complex::new(0.0, 0.0);
    let inv_m = 1.0 / m as f64;
    for c in &mut spec[1..last] {
        // −i·(a + ib) = b − ia, with the 1/M normalisation of the inverse FFT folded in.
        *c = Complex::new(c.im * inv_m, -c.re * inv_m);
    }
    inv.process_with_scratch(&mut spec, &mut buf, &mut scratch)?;
    buf.truncate(n);
    Ok(buf)
}

/// Analytic signal `z[n] = x[n] + i·H{x}[n]` (see [`hilbert_transform`] for the method).
pub fn analytic_signal(x: &[f64]) -> Result<Vec<Complex<f64>>> {
    let h = hilbert_transform(x)?;
    Ok(x.iter()
        .zip(h)
        .map(|(&re, im)| Complex::new(re, im))
        .collect())
}

/// Envelope `|z[n]| = sqrt(x[n]² + H{x}[n]²)`: the magnitude of the analytic signal
/// (see [`hilbert_transform`]). For `x = A(t)·cos(ωt + φ)` with `A` varying slowly compared
/// with `ω` (Bedrosian), this is `A(t)`.
///
/// Errors: empty signal, NaN/inf samples.
pub fn hilbert_envelope(x: &[f64]) -> Result<Vec<f64>> {
    let h = hilbert_transform(x)?;
    Ok(x.iter().zip(h).map(|(&re, im)| re.hypot(im)).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fast_len() {
        assert_eq!(next_fast_len(1), 1);
        assert_eq!(next_fast_len(7), 8);
        assert_eq!(next_fast_len(200_000), 200_000);
        assert_eq!(next_fast_len(1001), 1024);
    }

    #[test]
    fn envelope_of_am_tone() {
        // x = (1 + 0.5 cos 2π·20t)·cos 2π·2000t at 50 kHz: envelope 1 + 0.5 cos 2π·20t.
        // Away from the ends (10 % trimmed) the error must stay below 0.2 %.
        let fs = 50_000.0;
        let n = 25_000;
        let a = |t: f64| 1.0 + 0.5 * (std::f64::consts::TAU * 20.0 * t).cos();
        let x: Vec<f64> = (0..n)
            .map(|i| {
                let t = i as f64 / fs;
                a(t) * (std::f64::consts::TAU * 2000.0 * t).cos()
            })
            .collect();
        let e = hilbert_envelope(&x).unwrap();
        for i in n / 10..n - n / 10 {
            let want = a(i as f64 / fs);
            assert!(
                (e[i] - want).abs() < 2e-3 * want,
                "i={i} env={} want={want}",
                e[i]
            );
        }
        // Hilbert transform of cos is sin.
        let h = hilbert_transform(&x).unwrap();
        let i = n / 2;
        let t = i as f64 / fs;
        let want = a(t) * (std::f64::consts::TAU * 2000.0 * t).sin();
        assert!((h[i] - want).abs() < 2e-3, "h={} want={want}", h[i]);
    }

    #[test]
    fn envelope_rejects_bad_input() {
        assert!(hilbert_envelope(&[]).is_err());
        assert!(hilbert_envelope(&[1.0, f64::NAN]).is_err());
        assert_eq!(hilbert_envelope(&[0.0; 5]).unwrap(), vec![0.0; 5]);
    }
}
