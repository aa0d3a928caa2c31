//! Audio rendering: anti-aliasing, length, level, looping, pitch.

use crate::common;

use common::tones;
use squeal_signal::*;

const FS: f64 = 200_000.0;

fn as_f64(c: &AudioClip) -> Vec<f64> {
    c.samples.iter().map(|&v| v as f64).collect()
}

/// Highest amplitude-spectrum level (dB) of `y` (48 kHz) within `[lo, hi]` Hz.
fn max_db_in(spec: &Spectrum, lo: f64, hi: f64) -> f64 {
    let db = spec.to_db();
    spec.freq
        .iter()
        .zip(db)
        .filter(|(f, _)| **f >= lo && **f <= hi)
        .map(|(_, d)| d)
        .fold(DB_FLOOR, f64::max)
}

/// 1 kHz, 30 kHz and 40 kHz tones of equal amplitude in a 200 kHz signal: after rendering,
/// the aliases of 30 kHz (→ 18 kHz) and 40 kHz (→ 8 kHz), and everything else between 2 and
/// 20 kHz, are ≥ 60 dB below the 1 kHz tone (Hann amplitude spectrum of the output).
/// Also: length ≥ 2 s × 48 000, no sample beyond full scale, peak = 0.9 within 1e-6.
#[test]
fn ultrasonic_tones_do_not_alias() {
    let x = tones(
        &[
            (1000.0, 1.0, 0.0),
            (30_000.0, 1.0, 0.5),
            (40_000.0, 1.0, 1.0),
        ],
        FS,
        200_000,
    );
    let clip = render_audio(&x, FS, &AudioOptions::default()).unwrap();
    assert_eq!(clip.sample_rate, 48_000);
    assert!(clip.samples.len() >= 96_000, "{}", clip.samples.len());
    assert!(clip.samples.iter().all(|v| v.abs() <= 1.0));
    let peak = clip.samples.iter().fold(0.0f32, |m, v| m.max(v.abs()));
    assert!((peak - 0.9).abs() < 1e-6, "peak {peak}");
    let y = as_f64(&clip);
    let spec = amplitude_spectrum(&y, 48_000.0, &WelchOptions::default()).unwrap();
    let l1k = max_db_in(&spec, 950.0, 1050.0);
    let l18k = max_db_in(&spec, 17_800.0, 18_200.0);
    let l8k = max_db_in(&spec, 7_800.0, 8_200.0);
    let rest = max_db_in(&spec, 2_000.0, 20_000.0);
    assert!(l1k - l8k >= 60.0, "40 kHz alias only {} dB down", l1k - l8k);
    assert!(
        l1k - l18k >= 60.0,
        "30 kHz alias only {} dB down",
        l1k - l18k
    );
    assert!(l1k - rest >= 60.0, "2–20 kHz only {} dB down", l1k - rest);
}

/// Pass band: a 15 kHz tone resampled 200 kHz → 48 kHz keeps its amplitude within 0.05 dB
/// (flat-top amplitude spectrum), and a 19 kHz tone within 0.1 dB.
#[test]
fn resampler_passband_is_flat() {
    for (f, tol) in [(15_000.0, 0.05), (19_000.0, 0.1)] {
        let x = tones(&[(f, 1.0, 0.0)], FS, 100_000);
        let y = resample(&x, FS, 48_000.0, &ResampleOptions::default()).unwrap();
        assert_eq!(y.len(), (99_999.0f64 * 0.24).floor() as usize + 1);
        // skip the filter's edge transients (≈ 0.7 ms) at both ends
        let mid = &y[1000..y.len() - 1000];
        let spec = amplitude_spectrum(
            mid,
            48_000.0,
            &WelchOptions {
                window: Window::FlatTop,
                ..Default::default()
            },
        )
        .unwrap();
        let p = find_peaks(&spec, 1, &PeakOptions::default())[0];
        assert!(p.level_db.abs() < tol, "{f} Hz: {} dB", p.level_db);
    }
}

/// A 5 kHz tone stays at 5 kHz within one bin (48000/8192 Hz) — true pitch — both for a 1 s
/// input and a looped 0.3 s input.
#[test]
fn true_pitch() {
    for n in [200_000, 60_000] {
        let x = tones(&[(5000.0, 0.3, 0.2)], FS, n);
        let clip = render_audio(&x, FS, &AudioOptions::default()).unwrap();
        let f = dominant_frequency(&as_f64(&clip), 48_000.0)
            .unwrap()
            .unwrap();
        assert!((f - 5000.0).abs() < 48_000.0 / 8192.0, "n={n}: {f} Hz");
    }
}

/// A 0.3 s input is looped to exactly 2 s and says so; the splices are click-free: no
/// sample-to-sample step exceeds the largest step of a 0.9-amplitude 5 kHz sine by more
/// than 2 %. A 1 s input with `min_seconds = 0.5` is not looped (48 000 samples).
#[test]
fn short_input_is_looped() {
    let x = tones(&[(5000.0, 1.0, 0.0)], FS, 60_000);
    let clip = render_audio(&x, FS, &AudioOptions::default()).unwrap();
    assert!(clip.looped);
    assert_eq!(clip.samples.len(), 96_000);
    assert!((clip.source_seconds - 0.3).abs() < 1e-12);
    assert!((clip.duration() - 2.0).abs() < 1e-12);
    let max_step = 0.9 * 2.0 * (std::f64::consts::PI * 5000.0 / 48_000.0).sin();
    let worst = clip
        .samples
        .windows(2)
        .map(|w| (w[1] - w[0]).abs() as f64)
        .fold(0.0, f64::max);
    assert!(worst <= 1.02 * max_step, "step {worst} vs {max_step}");
    // fades: first and last samples are near zero
    assert!(clip.samples[0].abs() < 1e-3 && clip.samples[95_999].abs() < 1e-3);

    let x = tones(&[(5000.0, 1.0, 0.0)], FS, 200_000);
    let opts = AudioOptions {
        min_seconds: 0.5,
        ..Default::default()
    };
    let clip = render_audio(&x, FS, &opts).unwrap();
    assert!(!clip.looped);
    assert_eq!(clip.samples.len(), 48_000);
}

/// Upsampling: a 3 kHz tone at 20 kHz renders at 48 kHz at 3 kHz (within one bin) with its
/// image at 17 kHz ≥ 60 dB down.
#[test]
fn upsampling_from_low_rate() {
    let fs = 20_000.0;
    let x = tones(&[(3000.0, 1.0, 0.0)], fs, 20_000);
    let clip = render_audio(&x, fs, &AudioOptions::default()).unwrap();
    assert!(clip.samples.len() >= 96_000);
    let y = as_f64(&clip);
    let spec = amplitude_spectrum(&y, 48_000.0, &WelchOptions::default()).unwrap();
    let p = find_peaks(&spec, 1, &PeakOptions::default())[0];
    assert!((p.freq - 3000.0).abs() < spec.df, "{}", p.freq);
    let image = max_db_in(&spec, 16_800.0, 17_200.0);
    assert!(
        p.level_db - image >= 60.0,
        "image only {} dB down",
        p.level_db - image
    );
}

/// Silence in, silence out (no NaN); constant offset is removed (also silence).
#[test]
fn zero_input_gives_silence() {
    for v in [0.0, 3.0] {
        let clip = render_audio(&vec![v; 1000], FS, &AudioOptions::default()).unwrap();
        assert!(clip.samples.iter().all(|s| *s == 0.0));
        assert_eq!(clip.gain, 0.0);
        assert!(clip.looped);
        assert_eq!(clip.samples.len(), 96_000);
    }
    let one = render_audio(&[1.0], FS, &AudioOptions::default()).unwrap();
    assert!(one.samples.iter().all(|s| s.is_finite() && s.abs() <= 1.0));
}

/// Bad input gives typed errors.
#[test]
fn audio_rejects_bad_input() {
    let o = AudioOptions::default();
    assert_eq!(render_audio(&[], FS, &o), Err(SignalError::EmptySignal));
    assert!(render_audio(&[1.0, f64::NAN], FS, &o).is_err());
    assert!(render_audio(&[1.0; 10], 0.0, &o).is_err());
    for bad in [
        AudioOptions {
            sample_rate: 0,
            ..o
        },
        AudioOptions { peak: 1.5, ..o },
        AudioOptions {
            min_seconds: -1.0,
            ..o
        },
        AudioOptions {
            loop_fraction: 0.0,
            ..o
        },
        AudioOptions {
            resampler: ResampleOptions {
                passband_hz: 25_000.0,
                ..Default::default()
            },
            ..o
        },
    ] {
        assert!(
            matches!(
                render_audio(&[1.0; 10], FS, &bad),
                Err(SignalError::InvalidParameter { .. })
            ),
            "{bad:?}"
        );
    }
    assert!(resample(&[1.0; 10], FS, -48_000.0, &ResampleOptions::default()).is_err());
    // extreme ratios are refused instead of exhausting memory
    assert!(resample(&[1.0; 10], 1.0, 1e12, &ResampleOptions::default()).is_err());
    assert!(resample(&[1.0; 10], FS, 1e-6, &ResampleOptions::default()).is_err());
    let long = AudioOptions {
        min_seconds: 1e9,
        ..o
    };
    assert!(render_audio(&[1.0; 10], FS, &long).is_err());
    // heavy decimation still works (reduced table oversampling): 200 kHz → 100 Hz keeps a
    // 10 Hz cosine's amplitude within 0.1 dB in the middle of the record (every 10th output
    // sample is at a crest)
    let x = tones(&[(10.0, 1.0, std::f64::consts::FRAC_PI_2)], FS, 400_000);
    let y = resample(&x, FS, 100.0, &ResampleOptions::default()).unwrap();
    assert_eq!(y.len(), 200);
    let amp = y[60..140].iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!((20.0 * amp.log10()).abs() < 0.1, "{amp}");
}

/// RMS of the clip in dB re full scale, from its samples.
fn rms_db(c: &AudioClip) -> f64 {
    let y = as_f64(c);
    10.0 * (y.iter().map(|v| v * v).sum::<f64>() / y.len() as f64).log10()
}

/// A fixed reference instead of normalisation: a 1 kHz sine of amplitude A (m/s) with
/// full scale F renders at RMS `20·log10(A/(F·√2)) + gain` dB re full scale (±0.1 dB,
/// fades included), whatever its amplitude: ten times the vibration is 20 dB louder.
#[test]
fn fixed_reference_renders_the_stated_level() {
    let n = 200_000 * 3; // 3 s: no looping
    for (amp, gain) in [(0.5, 0.0), (0.05, 0.0), (0.05, 12.0), (1.0, -6.0)] {
        let x = tones(&[(1000.0, amp, 0.0)], FS, n);
        let opts = AudioOptions {
            full_scale: Some(2.0),
            gain_db: gain,
            ..AudioOptions::default()
        };
        let c = render_audio(&x, FS, &opts).unwrap();
        let want = 20.0 * (amp / (2.0 * 2f64.sqrt())).log10() + gain;
        assert!(
            (rms_db(&c) - want).abs() < 0.1,
            "A={amp} g={gain}: {} vs {want}",
            rms_db(&c)
        );
        assert!((c.rms_dbfs - want).abs() < 0.1, "{} vs {want}", c.rms_dbfs);
        assert_eq!(c.clipped, 0);
        assert!((c.gain - 10f64.powf(gain / 20.0) / 2.0).abs() < 1e-12);
    }
    // Beyond full scale: clipped and counted, never wrapped.
    let x = tones(&[(1000.0, 4.0, 0.0)], FS, n);
    let opts = AudioOptions {
        full_scale: Some(2.0),
        ..AudioOptions::default()
    };
    let c = render_audio(&x, FS, &opts).unwrap();
    assert!(c.clipped > 0);
    assert!(c.samples.iter().all(|v| v.abs() <= 1.0));
    // Bad references are refused.
    for bad in [
        AudioOptions {
            full_scale: Some(0.0),
            ..opts
        },
        AudioOptions {
            gain_db: f64::NAN,
            ..opts
        },
        AudioOptions {
            transpose_octaves: 9.0,
            ..opts
        },
    ] {
        assert!(render_audio(&x, FS, &bad).is_err());
    }
}

/// `transpose_octaves = −2` moves a 20 kHz line to 5 kHz (within one bin of the output's
/// spectrum), resampled (no 20 kHz left, no aliases), and keeps the true-pitch duration.
#[test]
fn transposition_moves_the_line_and_keeps_the_duration() {
    let n = 500_000; // 2.5 s at 200 kHz
    let x = tones(&[(20_000.0, 0.3, 0.0)], FS, n);
    let base = AudioOptions {
        full_scale: Some(1.0),
        ..AudioOptions::default()
    };
    let plain = render_audio(&x, FS, &base).unwrap();
    let low = render_audio(
        &x,
        FS,
        &AudioOptions {
            transpose_octaves: -2.0,
            ..base
        },
    )
    .unwrap();
    assert_eq!(plain.samples.len(), 120_000);
    assert_eq!(low.samples.len(), plain.samples.len(), "duration kept");
    assert!(!low.looped);
    let y = as_f64(&low);
    let opts = WelchOptions {
        seg_len: Some(16_384),
        ..WelchOptions::default()
    };
    let spec = amplitude_spectrum(&y, 48_000.0, &opts).unwrap();
    let p = find_peaks(&spec, 1, &PeakOptions::default())[0];
    assert!(
        (p.freq - 5000.0).abs() <= spec.df,
        "{} Hz (bin {})",
        p.freq,
        spec.df
    );
    // The level is kept (the same amplitude, a quarter of the frequency).
    assert!((rms_db(&low) - rms_db(&plain)).abs() < 0.2);
    assert!(max_db_in(&spec, 19_000.0, 21_000.0) < p.level_db - 60.0);
}
