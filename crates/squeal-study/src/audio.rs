//! A run as sound (`squeal listen`, `squeal.listen`): a velocity rendered at
//! true pitch (or transposed, a listening aid) at a fixed level reference,
//! and the WAV file's bytes. No files: the CLI and the Python package write
//! the bytes where they were asked to.

use crate::analysis::{si, state_pairs};
use crate::run::Run;
use crate::scenario::InputError;
use serde_json::{json, Value};
use squeal_signal::{AudioClip, Judgement};
use std::fmt::Write as _;

/// The level reference of every WAV squeal writes: a velocity of
/// `FULL_SCALE` m/s is full scale (sample value 1) at gain 0 dB. No
/// normalisation: a run that vibrates ten times as fast sounds 20 dB louder.
pub const FULL_SCALE: f64 = 2.0;

/// Frequencies above this (Hz) most adults do not hear.
pub const HEARING_LIMIT_HZ: f64 = 16_000.0;

/// How a WAV is rendered: the gain on top of [`FULL_SCALE`] and a listening
/// transposition.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SoundSettings {
    /// Gain in dB (0: full scale = [`FULL_SCALE`] m/s).
    pub gain_db: f64,
    /// Transposition in octaves (0: true pitch).
    pub transpose_octaves: f64,
}

impl SoundSettings {
    /// From `--gain` and `--transpose`, checked.
    pub fn from_flags(gain_db: f64, transpose: f64) -> Result<Self, InputError> {
        Self::checked(gain_db, transpose, ("--gain ", "--transpose "))
    }
    /// Checked: a gain within ±200 dB and a transposition within ±6
    /// octaves; a refusal names the value by `keys` (the CLI's flags, or
    /// the Python arguments).
    pub fn checked(gain_db: f64, transpose: f64, keys: (&str, &str)) -> Result<Self, InputError> {
        if !(gain_db.is_finite() && gain_db.abs() <= 200.0) {
            return Err(InputError(format!(
                "{}{gain_db}: must be a number of dB within ±200",
                keys.0
            )));
        }
        if !(transpose.is_finite() && transpose.abs() <= 6.0) {
            return Err(InputError(format!(
                "{}{transpose}: must be a number of octaves within ±6",
                keys.1
            )));
        }
        Ok(SoundSettings {
            gain_db,
            transpose_octaves: transpose,
        })
    }
    /// The line that says how loud the file is and why, for the terminal.
    pub fn describe(&self, clip: &AudioClip) -> String {
        let mut s = format!(
            "level: full scale = {FULL_SCALE} m/s at gain {:+.1} dB (no normalisation); RMS {:.1} dB re full scale",
            self.gain_db, clip.rms_dbfs
        );
        if self.transpose_octaves != 0.0 {
            let _ = write!(
                s,
                "; TRANSPOSED {:+} octaves (a listening aid, not the true pitch)",
                self.transpose_octaves
            );
        }
        if clip.clipped > 0 {
            let _ = write!(
                s,
                "; {} samples clipped: lower --gain by {:.0} dB",
                clip.clipped,
                (20.0 * (1.0 / clip.gain.max(1e-300)).log10())
                    .max(6.0)
                    .ceil()
            );
        }
        s
    }
    /// The same as JSON (`audio` in summary.json).
    pub fn json(&self, signal: &str, clip: &AudioClip) -> Value {
        json!({
            "signal": signal,
            "full_scale_m_per_s": FULL_SCALE,
            "gain_db": self.gain_db,
            "transpose_octaves": self.transpose_octaves,
            "rms_dbfs": clip.rms_dbfs,
            "clipped_samples": clip.clipped,
            "sample_rate": clip.sample_rate,
            "seconds": clip.duration(),
        })
    }
}

/// The velocity to hear by default: the squealing one, else the state's
/// velocity with the most energy (largest RMS over the judged window).
pub fn default_sound_signal(run: &Run, j: &Judgement) -> Option<String> {
    if let Some(q) = &j.squeal {
        return Some(q.velocity.clone());
    }
    let pairs = state_pairs(run);
    j.trends
        .iter()
        .filter(|t| t.rms > 0.0)
        .max_by(|a, b| a.rms.total_cmp(&b.rms))
        .and_then(|t| pairs.iter().find(|p| p.0 == t.name).map(|p| p.1.clone()))
        .or_else(|| pairs.first().map(|p| p.1.clone()))
}

/// A note when the squeal is above most adults' hearing, offering the
/// listening aid.
pub fn hearing_note(j: &Judgement, sound: &SoundSettings) -> Option<String> {
    let q = j.squeal.as_ref()?;
    if q.frequency_hz <= HEARING_LIMIT_HZ || sound.transpose_octaves != 0.0 {
        return None;
    }
    Some(format!(
        "note: the squeal ({}) is above most adults' hearing (about {}); to hear what the brake does, \
         render it two octaves lower with --transpose -2 (at {}; a listening aid, not the true pitch)",
        si(q.frequency_hz, "Hz", 4),
        si(HEARING_LIMIT_HZ, "Hz", 2),
        si(q.frequency_hz / 4.0, "Hz", 4)
    ))
}

/// A velocity `x` sampled at `fs` (Hz) as sound at 48 kHz, at the fixed
/// level reference ([`FULL_SCALE`], `sound.gain_db`), at true pitch unless
/// transposed. The resampler passes up to 22 kHz, so the disc–pad squeal at
/// 20.75 kHz is in the clip, not filtered out. The last fifth of the run
/// (the part the verdict judges steady) is looped when the run is shorter
/// than the clip.
pub fn render(x: &[f64], fs: f64, sound: &SoundSettings) -> Result<AudioClip, String> {
    let opts = squeal_signal::AudioOptions {
        loop_fraction: 0.2,
        full_scale: Some(FULL_SCALE),
        gain_db: sound.gain_db,
        transpose_octaves: sound.transpose_octaves,
        resampler: squeal_signal::ResampleOptions {
            passband_hz: 22_000.0,
            stopband_hz: 24_000.0,
            ..squeal_signal::ResampleOptions::default()
        },
        ..squeal_signal::AudioOptions::default()
    };
    squeal_signal::render_audio(x, fs, &opts).map_err(|e| format!("audio rendering failed: {e}"))
}

/// The bytes of a WAV file of `clip` (mono, 16-bit PCM, or 32-bit float if
/// `float`) with a RIFF `LIST`/`INFO` chunk whose `ICMT` (comment) names
/// the file (`file_name`), the level reference and the transposition:
/// players show it as the file's comment.
pub fn wav_bytes(clip: &AudioClip, float: bool, file_name: &str, sound: &SoundSettings) -> Vec<u8> {
    let spec = hound::WavSpec {
        channels: 1,
        sample_rate: clip.sample_rate,
        bits_per_sample: if float { 32 } else { 16 },
        sample_format: if float {
            hound::SampleFormat::Float
        } else {
            hound::SampleFormat::Int
        },
    };
    let mut cursor = std::io::Cursor::new(Vec::new());
    {
        // Writing to memory cannot fail.
        let mut w = hound::WavWriter::new(&mut cursor, spec).expect("a WAV header in memory");
        for &s in &clip.samples {
            if float {
                w.write_sample(s).expect("a sample in memory");
            } else {
                w.write_sample((s.clamp(-1.0, 1.0) * 32767.0).round() as i16)
                    .expect("a sample in memory");
            }
        }
        w.finalize().expect("a WAV in memory");
    }
    let mut bytes = cursor.into_inner();
    let comment = format!(
        "squeal: {file_name}; full scale = {FULL_SCALE} m/s at gain {:+.1} dB; transposed {:+} octaves",
        sound.gain_db, sound.transpose_octaves
    );
    let mut body = comment.into_bytes();
    body.push(0);
    if body.len() % 2 == 1 {
        body.push(0);
    }
    bytes.extend_from_slice(b"LIST");
    bytes.extend_from_slice(&((4 + 8 + body.len()) as u32).to_le_bytes());
    bytes.extend_from_slice(b"INFO");
    bytes.extend_from_slice(b"ICMT");
    bytes.extend_from_slice(&(body.len() as u32).to_le_bytes());
    bytes.extend_from_slice(&body);
    let riff = (bytes.len() - 8) as u32;
    bytes[4..8].copy_from_slice(&riff.to_le_bytes());
    bytes
}

/// What `listen` renders: the velocity `signal` of `run` (default
/// [`default_sound_signal`], else `fallback`) as a clip, with the run's
/// judgement. `Err` (bad input) names an unknown signal by `key` (the CLI's
/// `--signal `, Python's `signal = `) and lists the velocities.
pub fn listen(
    run: &Run,
    validity: f64,
    signal: Option<&str>,
    fallback: &str,
    sound: &SoundSettings,
    key: &str,
) -> Result<(String, AudioClip, Judgement), crate::StudyError> {
    let judgement = crate::analysis::judge_run(run, validity);
    let name = signal.map(str::to_string).unwrap_or_else(|| {
        default_sound_signal(run, &judgement).unwrap_or_else(|| fallback.to_string())
    });
    let x = run.column(&name).ok_or_else(|| {
        let vels: Vec<&str> = run
            .columns
            .iter()
            .filter(|c| c.starts_with('v') && *c != "v_rel")
            .map(String::as_str)
            .collect();
        InputError(format!(
            "{key}{name}: no such signal (velocities: {})",
            vels.join(", ")
        ))
    })?;
    let clip = render(x, run.sample_rate, sound).map_err(crate::StudyError::Numerical)?;
    Ok((name, clip, judgement))
}
