//! Welch PSD, amplitude spectrum, peak picking and spectrogram.

use crate::common;

use common::{tones, variance, Lcg};
use squeal_signal::*;

const FS: f64 = 200_000.0;

/// Parseval: ∫PSD df equals the variance within 1 % (noise + sines + offset, default options,
/// and also a rectangular window with odd, non-power-of-two segments).
#[test]
fn parseval_welch_matches_variance() {
    let n = 200_000;
    let mut rng = Lcg(12345);
    let s = tones(&[(1234.5, 0.7, 0.1), (7777.7, 0.2, 1.0)], FS, n);
    let x: Vec<f64> = s.iter().map(|v| v + rng.next() + 3.0).collect();
    let var = variance(&x);
    for opts in [
        WelchOptions::default(),
        WelchOptions {
            seg_len: Some(3001),
            overlap: 0.25,
            window: Window::Rect,
            remove_mean: true,
        },
        WelchOptions {
            window: Window::FlatTop,
            ..Default::default()
        },
    ] {
        let spec = welch(&x, FS, &opts).unwrap();
        let p = spec.total_power();
        assert!(
            (p - var).abs() < 0.01 * var,
            "{opts:?}: ∫PSD = {p}, variance = {var}"
        );
        assert_eq!(spec.scaling, Scaling::Density);
    }
    let spec = welch(&x, FS, &WelchOptions::default()).unwrap();
    assert_eq!(spec.len(), 8192 / 2 + 1);
    assert!((spec.df - FS / 8192.0).abs() < 1e-12);
    assert_eq!(spec.segments, (n - 8192) / 4096 + 1);
    // White-noise level: variance / (fs/2) = (1/12)/(1e5) per Hz, within 5 % on average
    // over a band without tones.
    let band = spec.band_power(40_000.0, 90_000.0) / 50_000.0;
    let want = (1.0 / 12.0) / (FS / 2.0);
    assert!(
        (band - want).abs() < 0.05 * want,
        "noise density {band} vs {want}"
    );
}

/// Off-bin sinusoids: Hann amplitude spectrum + parabolic interpolation gives frequencies
/// within 0.05 bin and peak amplitudes within 0.1 dB (required: 0.1 bin, 0.5 dB); flat-top
/// gives levels within 0.1 dB (interpolated and raw bin) and frequencies within 0.5 bin.
#[test]
fn sinusoid_peaks_frequency_and_level() {
    let truth = [
        (1234.5, 1.0, 0.2),
        (5017.3, 0.3, 1.1),
        (12_345.6, 0.05, 2.0),
        (31_111.1, 0.5, 0.7),
    ];
    let x = tones(&truth, FS, 200_000);
    let spec = amplitude_spectrum(&x, FS, &WelchOptions::default()).unwrap();
    let df = spec.df;
    let mut peaks = find_peaks(&spec, 4, &PeakOptions::default());
    assert_eq!(peaks.len(), 4);
    // strongest first
    assert!(peaks.windows(2).all(|w| w[0].level_db >= w[1].level_db));
    peaks.sort_by(|a, b| a.freq.total_cmp(&b.freq));
    for (p, &(f, a, _)) in peaks.iter().zip(&truth) {
        let want_db = 20.0 * a.log10();
        assert!(
            (p.freq - f).abs() < 0.05 * df,
            "freq {} vs {f} (err {:.3} bins)",
            p.freq,
            (p.freq - f) / df
        );
        assert!(
            (p.level_db - want_db).abs() < 0.1,
            "level {} dB vs {want_db} dB at {f} Hz",
            p.level_db
        );
        assert_eq!(p.bin, (f / df).round() as usize);
    }
    // Flat-top: both the interpolated level and the raw highest bin are accurate.
    let ft = amplitude_spectrum(
        &x,
        FS,
        &WelchOptions {
            window: Window::FlatTop,
            ..Default::default()
        },
    )
    .unwrap();
    let amp = ft.amplitude();
    let mut fpk = find_peaks(&ft, 4, &PeakOptions::default());
    fpk.sort_by(|a, b| a.freq.total_cmp(&b.freq));
    for (p, &(f, a, _)) in fpk.iter().zip(&truth) {
        let want_db = 20.0 * a.log10();
        assert!(
            (p.level_db - want_db).abs() < 0.1,
            "flattop {} vs {want_db}",
            p.level_db
        );
        assert!(
            (p.freq - f).abs() < 0.5 * df,
            "flattop freq {} vs {f}",
            p.freq
        );
        let k = ft.bin_of(f);
        let raw = amp[k - 1..=k + 1].iter().copied().fold(0.0, f64::max);
        assert!(
            (20.0 * (raw / a).log10()).abs() < 0.1,
            "raw flattop {raw} vs {a}"
        );
    }
}

/// Peak options: separation, band limits and relative threshold; DC is never a peak.
#[test]
fn peak_options_filter() {
    let x = tones(
        &[(1000.0, 1.0, 0.0), (1300.0, 0.5, 0.0), (5000.0, 0.001, 0.0)],
        FS,
        100_000,
    );
    let spec = amplitude_spectrum(&x, FS, &WelchOptions::default()).unwrap();
    let all = find_peaks(&spec, 10, &PeakOptions::default());
    assert!((all[0].freq - 1000.0).abs() < 0.1 * spec.df);
    assert!(all.iter().all(|p| p.bin > 0));
    let wide = find_peaks(
        &spec,
        10,
        &PeakOptions {
            min_separation_hz: Some(400.0),
            ..Default::default()
        },
    );
    assert!(
        wide.iter().all(|p| (p.freq - 1300.0).abs() > 50.0),
        "1300 Hz within 400 Hz"
    );
    assert!(all.iter().any(|p| (p.freq - 1300.0).abs() < 0.1 * spec.df));
    let band = find_peaks(
        &spec,
        1,
        &PeakOptions {
            min_freq_hz: 2000.0,
            ..Default::default()
        },
    );
    assert!((band[0].freq - 5000.0).abs() < 0.1 * spec.df);
    let strong = find_peaks(
        &spec,
        10,
        &PeakOptions {
            max_below_strongest_db: 20.0,
            ..Default::default()
        },
    );
    assert!(strong.iter().all(|p| p.level_db > all[0].level_db - 20.0));
    assert_eq!(strong.len(), 2, "{strong:?}");
    assert!(find_peaks(&spec, 0, &PeakOptions::default()).is_empty());
}

/// dB conversion never yields -inf/NaN; an all-zero signal has no peaks.
#[test]
fn db_floor_and_zero_signal() {
    let spec = welch(&[0.0; 1024], FS, &WelchOptions::default()).unwrap();
    let db = spec.to_db();
    assert!(db.iter().all(|v| *v == DB_FLOOR));
    assert!(find_peaks(&spec, 3, &PeakOptions::default()).is_empty());
    assert_eq!(power_to_db(f64::NAN), DB_FLOOR);
    assert!((power_to_db(100.0) - 20.0).abs() < 1e-12);
    assert_eq!(dominant_frequency(&[0.0; 1024], FS).unwrap(), None);
}

/// Bad input gives typed errors, never a panic.
#[test]
fn welch_rejects_bad_input() {
    let o = WelchOptions::default();
    assert_eq!(welch(&[], FS, &o), Err(SignalError::EmptySignal));
    assert!(matches!(
        welch(&[1.0, f64::NAN, 2.0], FS, &o),
        Err(SignalError::NonFinite { index: 1, .. })
    ));
    assert_eq!(
        welch(&[1.0; 10], 0.0, &o),
        Err(SignalError::InvalidRate(0.0))
    );
    assert!(welch(&[1.0; 10], f64::NAN, &o).is_err());
    let long = WelchOptions {
        seg_len: Some(11),
        ..o
    };
    assert_eq!(
        welch(&[1.0; 10], FS, &long),
        Err(SignalError::SegmentTooLong {
            seg_len: 11,
            len: 10
        })
    );
    let ov = WelchOptions { overlap: 1.0, ..o };
    assert!(matches!(
        welch(&[1.0; 10], FS, &ov),
        Err(SignalError::InvalidParameter {
            name: "overlap",
            ..
        })
    ));
    assert!(matches!(
        welch(&[1.0], FS, &o),
        Err(SignalError::TooShort { .. })
    ));
    assert!(amplitude_spectrum(&[], FS, &o).is_err());
    assert!(spectrogram(&[1.0; 10], FS, 16, 4, Window::Hann).is_err());
    assert!(spectrogram(&[1.0; 100], FS, 16, 0, Window::Hann).is_err());
    assert!(spectrogram(&[1.0; 100], -1.0, 16, 4, Window::Hann).is_err());
}

/// Spectrogram of a tone switching from 2 kHz to 6 kHz: each frame's maximum is at the right
/// frequency (within one bin), times are frame centres, and a single frame has the same
/// scaling as Welch with one segment (within 1e-9 dB).
#[test]
fn spectrogram_tracks_frequency_switch() {
    let n = 100_000;
    let x: Vec<f64> = (0..n)
        .map(|i| {
            let t = i as f64 / FS;
            let f = if i < n / 2 { 2000.0 } else { 6000.0 };
            (std::f64::consts::TAU * f * t).sin()
        })
        .collect();
    let (seg, hop) = (1024, 512);
    let sg = spectrogram(&x, FS, seg, hop, Window::Hann).unwrap();
    assert_eq!(sg.n_times(), (n - seg) / hop + 1);
    assert_eq!(sg.n_freqs(), seg / 2 + 1);
    assert_eq!(sg.psd_db.len(), sg.n_times() * sg.n_freqs());
    assert!((sg.times[0] - seg as f64 / 2.0 / FS).abs() < 1e-12);
    assert!((sg.times[1] - sg.times[0] - hop as f64 / FS).abs() < 1e-12);
    for i in 0..sg.n_times() {
        let row = sg.row(i).unwrap();
        let k = (0..row.len()).fold(0, |b, k| if row[k] > row[b] { k } else { b });
        let t0 = i * hop;
        let want = if t0 + seg <= n / 2 {
            2000.0
        } else if t0 >= n / 2 {
            6000.0
        } else {
            continue;
        };
        assert!(
            (sg.freqs[k] - want).abs() <= sg.df,
            "frame {i}: {} Hz",
            sg.freqs[k]
        );
    }
    let one = welch(
        &x[..seg],
        FS,
        &WelchOptions {
            seg_len: Some(seg),
            ..Default::default()
        },
    )
    .unwrap()
    .to_db();
    for (a, b) in one.iter().zip(sg.row(0).unwrap()) {
        assert!((a - b).abs() < 1e-9);
    }
    assert!(sg.get(0, seg).is_none());
    assert!(sg.row(sg.n_times()).is_none());
}

/// Dominant frequency and RMS on a known signal.
#[test]
fn dominant_frequency_and_rms() {
    let x = tones(&[(3210.0, 2.0, 0.0), (800.0, 0.5, 0.0)], FS, 200_000);
    let f = dominant_frequency(&x, FS).unwrap().unwrap();
    assert!((f - 3210.0).abs() < 0.1 * FS / 8192.0, "{f}");
    // RMS of a sum of tones = sqrt(Σ a²/2); tail over 25 %.
    let want = ((4.0 + 0.25) / 2.0f64).sqrt();
    assert!((rms(&x).unwrap() - want).abs() < 1e-3 * want);
    assert!((rms_tail(&x, 0.25).unwrap() - want).abs() < 1e-3 * want);
    assert!((rms_tail(&[1.0, 1.0, 3.0], 0.2).unwrap() - 3.0).abs() < 1e-15);
    assert!(rms_tail(&x, 0.0).is_err());
    assert!(rms_tail(&x, 1.5).is_err());
    assert_eq!(rms(&[]), Err(SignalError::EmptySignal));
}
