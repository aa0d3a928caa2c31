//! Shards of a map, a sweep or `reproduce`, gathered by `merge`
//! (`squeal merge DIR… --out DIR`).
//!
//! `squeal map … --shard K/N` computes the points whose flat index `i`
//! (row-major over y then x, see [`squeal_study::map::point`]) has
//! `i mod N = K` — interleaved, so that the expensive corners of a grid
//! spread over every task — and writes, through the staging swap (a shard
//! folder exists only once it is complete):
//!
//! - `shard.json`: the study it belongs to (command, squeal version, the
//!   resolved scenario and a hash of it, both axes with every value, whether
//!   it simulates), `k`, `n`, how its indices are chosen and how many, and
//!   the length and hash of `part.csv`;
//! - `part.csv`: its rows of `map.csv`, each led by its flat index, numbers
//!   written exactly (`{:e}` round-trips every f64).
//!
//! `merge` refuses (exit 2, one line with the reason) shards of different
//! studies, a missing shard (naming its point indices), a shard given twice,
//! and a shard whose `part.csv` is not the one its manifest describes
//! (truncated, edited); then it writes `map.csv` and the pictures through
//! `map::write_map`, the writer of the unsharded map, so
//! the result is byte-identical to it.
//!
//! `squeal reproduce … --shard K/N` measures the thesis sets whose index
//! `i` (set `i + 1`) has `i mod N = K` and writes `shard.json`, `part.json`
//! (each set's results, every number as exact text, see
//! [`squeal_study::reproduce::exact`]) and, unless `--no-figures`, the sets'
//! Appendix A pictures under `figures/` (each listed in the manifest with
//! its length and hash). `merge` recognises such shards by their manifest's
//! `study.command`, refuses them for the same reasons as map shards (a
//! missing shard names its sets), rebuilds the 40 scenarios with
//! [`squeal_study::reproduce::prepared_sets`] (and refuses shards made from
//! other sets), copies the pictures and ends through
//! `reproduce::finish` — the same sweeps, conclusions,
//! map and report as the unsharded `reproduce`, byte for byte.

use crate::RunError;
use serde_json::{json, Value};
use squeal_study::map::Axis;
use squeal_study::scenario::InputError;
use std::path::Path;

/// The manifest of a shard.
pub const SHARD_FILE: &str = "shard.json";
/// A shard's rows.
pub const PART_FILE: &str = "part.csv";
/// A `reproduce` shard's sets.
pub const SETS_FILE: &str = "part.json";
/// The `format` of [`SHARD_FILE`].
pub const FORMAT: &str = "squeal-shard-1";

/// Shard `k` of `n` (`0 ≤ k < n`): the flat indices `i` with `i mod n = k`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// Which slice, from 0.
    pub k: usize,
    /// How many slices.
    pub n: usize,
}

impl Shard {
    /// The default output folder's name of a study called `base`: `base`, or
    /// `base-shard-K-of-N` for a shard.
    pub fn folder(base: &str, shard: Option<Shard>) -> String {
        match shard {
            Some(s) => format!("{base}-shard-{}-of-{}", s.k, s.n),
            None => base.to_string(),
        }
    }

    /// Parse `K/N` (the `--shard` flag).
    pub fn parse(s: &str) -> Result<Shard, InputError> {
        let bad = |why: &str| InputError(format!("--shard {s}: {why}"));
        let (k, n) = s
            .split_once('/')
            .ok_or_else(|| bad("expected K/N, e.g. 0/4"))?;
        let k: usize = k
            .trim()
            .parse()
            .map_err(|_| bad("K must be a whole number ≥ 0"))?;
        let n: usize = n
            .trim()
            .parse()
            .map_err(|_| bad("N must be a whole number ≥ 1"))?;
        if n == 0 {
            return Err(bad("N must be at least 1"));
        }
        if k >= n {
            return Err(bad("K counts from 0 and must be less than N"));
        }
        Ok(Shard { k, n })
    }

    /// This shard's flat indices of a grid of `total` points, ascending.
    pub fn points(self, total: usize) -> Vec<usize> {
        (self.k..total).step_by(self.n).collect()
    }
}

/// FNV-1a, 64 bits: a fingerprint (not a cryptographic hash) of a
/// scenario's content or a part's bytes, to tell studies apart and find a
/// changed file.
pub fn fnv1a(bytes: &[u8]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in bytes {
        h ^= u64::from(*b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    format!("{h:016x}")
}

pub(crate) fn axis_json(a: &Axis, label: &str) -> Value {
    let values: Vec<String> = a.values.iter().map(|v| format!("{v:e}")).collect();
    json!({ "name": a.name, "log": a.log, "label": label, "values": values })
}

pub(crate) fn write_file(path: &Path, bytes: &[u8]) -> Result<(), RunError> {
    std::fs::write(path, bytes)
        .map_err(|e| RunError::Io(format!("cannot write {}: {e}", path.display())))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_point_is_in_exactly_one_shard() {
        for total in [0, 1, 5, 12, 13] {
            for n in 1..=8 {
                let mut seen = vec![0; total];
                for k in 0..n {
                    for i in (Shard { k, n }).points(total) {
                        assert_eq!(i % n, k);
                        seen[i] += 1;
                    }
                }
                assert!(seen.iter().all(|c| *c == 1), "{total} points, {n} shards");
            }
        }
    }

    #[test]
    fn shard_flag_is_checked() {
        assert_eq!(Shard::parse("2/7").unwrap(), Shard { k: 2, n: 7 });
        for bad in ["7/7", "1/0", "x/2", "3", "-1/2"] {
            let e = Shard::parse(bad).unwrap_err().0;
            assert!(e.starts_with(&format!("--shard {bad}:")), "{e}");
        }
    }

    #[test]
    fn exponent_text_round_trips_every_f64() {
        for v in [0.1, 1.0 / 3.0, 6.02e23, -2.5e-310, f64::MAX, f64::INFINITY] {
            let s = format!("{v:e}");
            assert_eq!(s.parse::<f64>().unwrap().to_bits(), v.to_bits(), "{s}");
        }
        assert!(format!("{:e}", f64::NAN).parse::<f64>().unwrap().is_nan());
    }
}
