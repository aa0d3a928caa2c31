//! Short-time power spectra (spectrogram).

use crate::error::{check_rate, check_signal, invalid, Result, SignalError};
use crate::spectrum::{is_doubled, power_to_db, FrameFft};
use crate::window::Window;

/// A spectrogram: one density-scaled one-sided PSD (dB re 1 unit²/Hz) per frame.
///
/// `psd_db` is stored flat, row-major with one row per frame:
/// `psd_db[i·freqs.len() + k]` is frame `i` (time `times[i]`) at frequency `freqs[k]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Spectrogram {
    /// Frame centre times in seconds, `(i·hop + seg_len/2) / fs`.
    pub times: Vec<f64>,
    /// Bin frequencies in Hz, `k·fs/seg_len`, `k = 0 ..= seg_len/2`.
    pub freqs: Vec<f64>,
    /// PSD in dB (floored at [`crate::DB_FLOOR`]), row-major `[frame][bin]`.
    pub psd_db: Vec<f64>,
    /// Bin spacing in Hz.
    pub df: f64,
}

impl Spectrogram {
    /// Number of frames (rows).
    pub fn n_times(&self) -> usize {
        self.times.len()
    }

    /// Number of frequency bins (columns).
    pub fn n_freqs(&self) -> usize {
        self.freqs.len()
    }

    /// The PSD row (dB per bin) of frame `i`, or `None` if out of range.
    pub fn row(&self, i: usize) -> Option<&[f64]> {
        let nf = self.n_freqs();
        self.psd_db.get(i * nf..(i + 1) * nf)
    }

    /// Level in dB of frame `i` at bin `k`, or `None` if out of range.
    pub fn get(&self, i: usize, k: usize) -> Option<f64> {
        if k >= self.n_freqs() {
            return None;
        }
        self.psd_db.get(i * self.n_freqs() + k).copied()
    }

    /// Maximum level in dB over all frames and bins ([`crate::DB_FLOOR`] if empty).
    pub fn max_db(&self) -> f64 {
        self.psd_db
            .iter()
            .copied()
            .fold(crate::spectrum::DB_FLOOR, f64::max)
    }
}

/// Spectrogram of `x`: frames of `seg_len` samples every `hop` samples, each mean-removed,
/// windowed and transformed; frame `i` holds the one-sided PSD
/// `P_i[k] = c_k |X_i[k]|² / (fs·Σw²)` (`c_k = 2` except at DC and Nyquist) in dB — the same
/// scaling as a single-segment [`crate::welch`]. Trailing samples that do not fill a frame
/// are not used.
///
/// Errors: empty signal, NaN/inf samples, `fs ≤ 0`, `seg_len < 2`, `seg_len` longer than the
/// signal, `hop = 0`.
pub fn spectrogram(
    x: &[f64],
    fs: f64,
    seg_len: usize,
    hop: usize,
    window: Window,
) -> Result<Spectrogram> {
    check_signal(x)?;
    check_rate(fs)?;
    if seg_len < 2 {
        return Err(invalid("seg_len", format!("must be >= 2, got {seg_len}")));
    }
    if seg_len > x.len() {
        return Err(SignalError::SegmentTooLong {
            seg_len,
            len: x.len(),
        });
    }
    if hop == 0 {
        return Err(invalid("hop", "must be >= 1"));
    }
    let frames = (x.len() - seg_len) / hop + 1;
    let nf = seg_len / 2 + 1;
    let mut frame = FrameFft::new(seg_len, window);
    let scale = 1.0 / (fs * frame.window_sum_sq());
    let mut psd_db = vec![0.0; frames * nf];
    let mut acc = vec![0.0; nf];
    for (i, row) in psd_db.chunks_exact_mut(nf).enumerate() {
        acc.iter_mut().for_each(|a| *a = 0.0);
        let start = i * hop;
        frame.accumulate_power(&x[start..start + seg_len], true, &mut acc)?;
        for (k, (dst, p)) in row.iter_mut().zip(&acc).enumerate() {
            let c = if is_doubled(k, seg_len) { 2.0 } else { 1.0 };
            *dst = power_to_db(c * scale * p);
        }
    }
    let df = fs / seg_len as f64;
    Ok(Spectrogram {
        times: (0..frames)
            .map(|i| (i * hop) as f64 / fs + seg_len as f64 / (2.0 * fs))
            .collect(),
        freqs: (0..nf).map(|k| k as f64 * df).collect(),
        psd_db,
        df,
    })
}
