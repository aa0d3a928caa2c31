//! Every eigenvalue of steady sliding along a one-parameter sweep, modes
//! tracked continuously by shape.

use crate::error::{Cancel, StudyError};
use crate::model::AnyModel;
use crate::scenario::InputError;
use nalgebra::DMatrix;
use squeal_core::stability::sweep::{sweep, Sweep, SweepOptions};
use squeal_core::stability::{state_matrix, StabilityError};

/// The state matrix `A = ∂f/∂z` and equilibrium of any model, as runtime-sized values.
pub fn model_state_matrix(model: &AnyModel) -> Result<(DMatrix<f64>, Vec<f64>), StabilityError> {
    crate::with_model!(model, m => {
        let (z, a) = state_matrix(m)?;
        let n = z.len();
        Ok((DMatrix::from_fn(n, n, |i, j| a[i][j]), z.to_vec()))
    }, lumped l => {
        let (z, a) = squeal_core::stability::lumped::state_matrix(l)?;
        Ok((a, z))
    })
}

/// Sweep `name` over `values` for any model (built-in or lumped),
/// tracking every mode by shape ([`squeal_core::stability::sweep`]). On
/// failure, also the parameter value where it happened.
pub fn sweep_at(
    model: &AnyModel,
    name: &str,
    values: &[f64],
    cancel: &Cancel,
) -> Result<Sweep, (StabilityError, f64)> {
    let mut at = f64::NAN;
    sweep(
        values,
        |p| {
            at = p;
            if cancel.is_cancelled() {
                return Err(StabilityError::BadInput("interrupted".into()));
            }
            let mut m = model.clone();
            m.set(name, p)?;
            m.validate()?;
            model_state_matrix(&m)
        },
        &SweepOptions::default(),
    )
    .map_err(|e| (e, at))
}

/// [`sweep_at`] with its failures as study errors: `spec` is the sweep as
/// the user wrote it (`NAME=LO:HI:N`), quoted as `--param SPEC` in messages.
pub fn sweep_model(
    model: &AnyModel,
    name: &str,
    values: &[f64],
    spec: &str,
    cancel: &Cancel,
) -> Result<Sweep, StudyError> {
    let r = sweep_at(model, name, values, cancel);
    cancel.check()?;
    r.map_err(|(e, at)| match e {
        StabilityError::Param(_) => StudyError::Input(InputError(format!("--param {spec}: {e}"))),
        StabilityError::NoSteadySliding(_) => {
            StudyError::Input(InputError(format!("--param {spec}: at {name} = {at}: {e}")))
        }
        other => StudyError::Numerical(format!("eigen-analysis at {name} = {at}: {other}")),
    })
}

/// Sharded sweeps: contiguous slices of the values, each computed with two
/// values of the slice before it, and merged into the [`Sweep`] of the
/// whole.
///
/// Why this is exact. The tracking ([`squeal_core::stability::sweep`])
/// pairs the eigenpairs of value `k` with those of `k − 1`, with each
/// branch's eigenvalue extrapolated from `k − 2` and `k − 1`; its result
/// does not depend on how the branches are numbered. So the pairing at
/// value `k` depends on the pairings before it only through the pairing of
/// `k − 2` with `k − 1`. Slice `K` owns the values `[a, b)` and computes
/// `[a − 2, b)`: at `a − 1` it pairs without extrapolation (it has no
/// history), from `a` on with. The same eigen-solve gives the same bits, so
/// the merge reads the renumbering of slice `K`'s branches off the
/// eigenvalues at `a − 2` and checks that at `a − 1` they pair as in slice
/// `K − 1`; then every later pairing is the whole sweep's, bit for bit. If
/// that check fails (the extrapolation changed a pairing right at the
/// boundary) or a double eigenvalue makes the renumbering ambiguous, the
/// merge refuses and names the value. Onsets are taken from the slice that
/// owns the interval's upper value; which listed mode changes, and the
/// listed modes themselves, are recomputed over the merged eigenvalues.
pub mod shard {
    use nalgebra::Complex;
    use serde_json::{json, Value};
    use squeal_core::stability::sweep::{listed_branches, onset_mode, Onset, Sweep};
    use squeal_core::stability::Direction;
    use std::ops::Range;

    /// The values slice `k` of `n` owns, and the values it computes (two
    /// more before, within the sweep). Contiguous, every value owned once.
    pub fn slice(values: usize, k: usize, n: usize) -> (Range<usize>, Range<usize>) {
        let own = k * values / n..(k + 1) * values / n;
        let computed = own.start.saturating_sub(2)..own.end;
        (own, computed)
    }

    /// What a slice computed: eigenvalues from `start` on, and the onsets
    /// whose interval ends at a value it owns.
    #[derive(Debug, Clone, PartialEq)]
    pub struct Part {
        /// Index of the first computed value in the whole sweep.
        pub start: usize,
        /// `lambda[i][b]`: eigenvalue of the slice's branch `b` at value `start + i`.
        pub lambda: Vec<Vec<Complex<f64>>>,
        /// `(k, onset)`: an onset between values `k − 1` and `k`.
        pub onsets: Vec<(usize, Onset)>,
    }

    /// The part of slice `k` of `n` from the sweep `sw` of its computed
    /// values `values[computed]` (see [`slice()`]).
    pub fn part_of(values: &[f64], k: usize, n: usize, sw: &Sweep) -> Part {
        let (own, computed) = slice(values.len(), k, n);
        let local = &values[computed.clone()];
        // The interval of each onset: the first whose ends enclose it.
        let onsets = sw
            .onsets
            .iter()
            .filter_map(|o| {
                let i = (1..local.len()).find(|&i| {
                    let (a, b) = (local[i - 1], local[i]);
                    a.min(b) <= o.value && o.value <= a.max(b)
                })?;
                let g = computed.start + i;
                own.contains(&g).then_some((g, *o))
            })
            .collect();
        Part {
            start: computed.start,
            lambda: sw.lambda.clone(),
            onsets,
        }
    }

    fn x(v: f64) -> String {
        format!("{v:e}")
    }

    /// A part as JSON, every number as exact text (`{:e}`).
    pub fn to_json(p: &Part) -> Value {
        json!({
            "start": p.start,
            "lambda": p.lambda.iter().map(|row| {
                row.iter().map(|l| format!("{} {}", x(l.re), x(l.im))).collect::<Vec<_>>()
            }).collect::<Vec<_>>(),
            "onsets": p.onsets.iter().map(|(k, o)| json!({
                "k": k,
                "value": x(o.value),
                "freq_hz": x(o.freq_hz),
                "direction": o.direction,
                "coalescence": o.coalescence,
            })).collect::<Vec<_>>(),
        })
    }

    /// Read a part back; the error names the field.
    pub fn from_json(v: &Value) -> Result<Part, String> {
        let num = |s: &str, what: &str| {
            s.parse::<f64>()
                .map_err(|_| format!("{what}: bad number {s:?}"))
        };
        let start = v["start"].as_u64().ok_or("start: not a whole number")? as usize;
        let lambda = v["lambda"]
            .as_array()
            .ok_or("lambda: not a list")?
            .iter()
            .map(|row| {
                row.as_array()
                    .ok_or_else(|| "lambda: not a list".to_string())?
                    .iter()
                    .map(|l| {
                        let s = l.as_str().ok_or("lambda: not text")?;
                        let (re, im) = s.split_once(' ').ok_or("lambda: expected \"RE IM\"")?;
                        Ok(Complex::new(num(re, "lambda")?, num(im, "lambda")?))
                    })
                    .collect::<Result<Vec<_>, String>>()
            })
            .collect::<Result<Vec<_>, String>>()?;
        let onsets = v["onsets"]
            .as_array()
            .ok_or("onsets: not a list")?
            .iter()
            .map(|o| {
                let k = o["k"].as_u64().ok_or("onsets.k: not a whole number")? as usize;
                let direction = match o["direction"].as_str() {
                    Some("destabilising") => Direction::Destabilising,
                    Some("stabilising") => Direction::Stabilising,
                    _ => return Err("onsets.direction: unknown".to_string()),
                };
                let text = |key: &str| o[key].as_str().ok_or(format!("onsets.{key}: not text"));
                Ok((
                    k,
                    Onset {
                        value: num(text("value")?, "onsets.value")?,
                        freq_hz: num(text("freq_hz")?, "onsets.freq_hz")?,
                        mode: None,
                        direction,
                        coalescence: o["coalescence"]
                            .as_bool()
                            .ok_or("onsets.coalescence: not true/false")?,
                    },
                ))
            })
            .collect::<Result<Vec<_>, String>>()?;
        Ok(Part {
            start,
            lambda,
            onsets,
        })
    }

    fn bits(l: Complex<f64>) -> (u64, u64) {
        (l.re.to_bits(), l.im.to_bits())
    }

    /// Merge the parts of slices `0 … n − 1` (in that order) of a sweep of
    /// `values` into the whole sweep (`mac` is not kept: empty). Errors say
    /// which slice and value do not fit.
    pub fn merge(values: &[f64], parts: &[Part]) -> Result<Sweep, String> {
        let n = parts.len();
        let mut lambda: Vec<Vec<Complex<f64>>> = Vec::with_capacity(values.len());
        let mut onsets: Vec<(usize, Onset)> = Vec::new();
        for (k, p) in parts.iter().enumerate() {
            let (own, computed) = slice(values.len(), k, n);
            if p.start != computed.start || p.lambda.len() != computed.len() {
                return Err(format!(
                    "slice {k}/{n} should hold values {}–{}, it holds {} from {}",
                    computed.start,
                    computed.end.saturating_sub(1),
                    p.lambda.len(),
                    p.start
                ));
            }
            if p.lambda
                .iter()
                .any(|r| Some(r.len()) != lambda.first().or(p.lambda.first()).map(Vec::len))
            {
                return Err(format!("slice {k}/{n}: the number of eigenvalues differs"));
            }
            let shared = own.start - computed.start;
            let pi: Vec<usize> = if shared == 0 {
                (0..p.lambda.first().map_or(0, Vec::len)).collect()
            } else {
                // The renumbering, from the eigenvalues at the first shared value.
                let at = &lambda[computed.start];
                let mut pi = Vec::with_capacity(at.len());
                for l in &p.lambda[0] {
                    let m: Vec<usize> =
                        (0..at.len()).filter(|&b| bits(at[b]) == bits(*l)).collect();
                    if m.len() != 1 {
                        return Err(format!(
                            "slice {k}/{n}: a repeated eigenvalue at {} makes its modes ambiguous; use fewer shards",
                            values[computed.start]
                        ));
                    }
                    pi.push(m[0]);
                }
                for i in 1..shared {
                    let g = computed.start + i;
                    if (0..pi.len()).any(|b| bits(p.lambda[i][b]) != bits(lambda[g][pi[b]])) {
                        return Err(format!(
                            "slices {}/{n} and {k}/{n} pair the modes differently at {} (a boundary the tracking's extrapolation decides); use fewer or other shards",
                            k - 1,
                            values[g]
                        ));
                    }
                }
                pi
            };
            for row in &p.lambda[shared..] {
                let mut r = vec![Complex::new(0.0, 0.0); row.len()];
                for (b, l) in row.iter().enumerate() {
                    r[pi[b]] = *l;
                }
                lambda.push(r);
            }
            onsets.extend(p.onsets.iter().copied());
        }
        if lambda.len() != values.len() {
            return Err(format!(
                "the slices hold {} of {} values",
                lambda.len(),
                values.len()
            ));
        }
        let listed = listed_branches(&lambda);
        onsets.sort_by_key(|o| o.0);
        let onsets = onsets
            .into_iter()
            .map(|(k, mut o)| {
                if k == 0 || k >= lambda.len() {
                    return Err(format!("an onset in no interval (value index {k})"));
                }
                o.mode = onset_mode(&listed, &lambda[k - 1], &lambda[k]);
                Ok(o)
            })
            .collect::<Result<Vec<_>, String>>()?;
        Ok(Sweep {
            values: values.to_vec(),
            lambda,
            mac: Vec::new(),
            listed,
            onsets,
        })
    }
}
