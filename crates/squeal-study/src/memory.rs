//! The memory this process may still take (issue 24, class 2): the least of
//! its address-space limit (`ulimit -v`, `RLIMIT_AS`, less the address
//! space already mapped), its cgroup's limit (`memory.max` less
//! `memory.current`, cgroup v2) and the machine's available memory
//! (`MemAvailable`). A run that would need more is refused before it starts,
//! with the memory it would need, instead of being killed by the allocator.
//!
//! This is the one place of the study library that looks at the machine
//! (`/proc` and `/sys/fs/cgroup`); each reading that fails is left out, and
//! when none succeeds nothing is refused.

use std::path::Path;

/// What bounds the memory this process may still take.
#[derive(Debug, Clone, PartialEq)]
pub struct Headroom {
    /// Bytes the process may still allocate.
    pub bytes: f64,
    /// Which limit binds, in words ("the address-space limit (ulimit -v)").
    pub bound_by: &'static str,
}

fn read_small(path: &Path) -> Option<String> {
    // /proc and /sys files are small and regular-looking but report a
    // size of 0; read at most 64 kB.
    use std::io::Read;
    let mut s = String::new();
    std::fs::File::open(path)
        .ok()?
        .take(64 * 1024)
        .read_to_string(&mut s)
        .ok()?;
    Some(s)
}

/// `key:   1234 kB` from a /proc file, in bytes.
fn proc_kb(text: &str, key: &str) -> Option<f64> {
    let line = text.lines().find(|l| l.starts_with(key))?;
    let kb: f64 = line[key.len()..]
        .trim_start_matches(':')
        .split_whitespace()
        .next()?
        .parse()
        .ok()?;
    Some(kb * 1024.0)
}

fn address_space() -> Option<f64> {
    let lim = rustix::process::getrlimit(rustix::process::Resource::As);
    let max = lim.current? as f64;
    let used = proc_kb(&read_small(Path::new("/proc/self/status"))?, "VmSize").unwrap_or(0.0);
    Some((max - used).max(0.0))
}

fn cgroup() -> Option<f64> {
    // cgroup v2: one line "0::/path".
    let own = read_small(Path::new("/proc/self/cgroup"))?;
    let rel = own.lines().find_map(|l| l.strip_prefix("0::"))?.trim();
    let dir = Path::new("/sys/fs/cgroup").join(rel.trim_start_matches('/'));
    let max = read_small(&dir.join("memory.max"))?;
    let max: f64 = max.trim().parse().ok()?; // "max" (no limit) fails here
    let current: f64 = read_small(&dir.join("memory.current"))?
        .trim()
        .parse()
        .ok()?;
    Some((max - current).max(0.0))
}

fn physical() -> Option<f64> {
    proc_kb(&read_small(Path::new("/proc/meminfo"))?, "MemAvailable")
}

/// The memory this process may still take, and what bounds it; `None` if
/// no limit could be read.
pub fn headroom() -> Option<Headroom> {
    let candidates = [
        (address_space(), "the address-space limit (ulimit -v)"),
        (cgroup(), "the cgroup memory limit (memory.max)"),
        (physical(), "the machine's available memory (MemAvailable)"),
    ];
    candidates
        .into_iter()
        .filter_map(|(b, what)| {
            b.map(|bytes| Headroom {
                bytes,
                bound_by: what,
            })
        })
        .min_by(|a, b| a.bytes.total_cmp(&b.bytes))
}

/// `Err(message)` if `need` bytes (for `what`) exceed the [`headroom`].
pub fn check(need: f64, what: &str) -> Result<(), String> {
    match headroom() {
        Some(h) if need > h.bytes => Err(format!(
            "{what} needs about {:.2} GB of memory; this process may take {:.2} GB more, bound by {}",
            need / 1e9,
            h.bytes / 1e9,
            h.bound_by
        )),
        _ => Ok(()),
    }
}

/// Below this many bytes (64 MiB) no memory check is made: every machine
/// squeal runs on has that, and a map of small runs reads no `/proc` files.
pub const MEMORY_CHECK_FROM: f64 = 64.0 * 1024.0 * 1024.0;

/// Memory of the dense analyses of a lumped model with `n` dofs (bytes):
/// its steady-sliding Jacobian (`n × 2n`), the state matrix or the
/// projection's dense eigenproblem, as `300 n²`. Measured: a 500-dof model
/// peaks at 68 MB, a 1000-dof one at 277 MB (`/usr/bin/time -f %M squeal
/// stability`), 272–277 bytes per n².
pub fn dense_analysis_bytes(n: usize) -> f64 {
    300.0 * (n as f64) * (n as f64)
}

/// Memory of the sparse analysis of a lumped model with `n` dofs and
/// `nonzeros` stored matrix entries (bytes): the Lanczos vectors and their
/// `M` products (`16 n` per vector, a few hundred vectors), the sparse
/// factorisation's fill (taken as 40 entries of 12 bytes per nonzero) and
/// the kept eigenvectors
/// ([`squeal_core::stability::projected::VECTOR_BUDGET`]).
pub fn sparse_analysis_bytes(n: usize, nonzeros: usize) -> f64 {
    let vectors = 16.0 * n as f64 * 400.0;
    let factor = 480.0 * nonzeros as f64;
    let kept = 16.0 * squeal_core::stability::projected::VECTOR_BUDGET as f64;
    vectors + factor + kept
}

/// The memory an analysis of a lumped model of `dofs` dofs and `nonzeros`
/// stored matrix entries takes (bytes) and what it is: sparse above
/// [`squeal_core::linear::SPARSE_FROM_DOFS`] dofs, dense below.
pub fn analysis_bytes(dofs: usize, nonzeros: usize) -> (f64, &'static str) {
    if dofs > squeal_core::linear::SPARSE_FROM_DOFS {
        (
            sparse_analysis_bytes(dofs, nonzeros),
            "its sparse steady-sliding and eigen-analysis",
        )
    } else {
        (
            dense_analysis_bytes(dofs),
            "its dense steady-sliding and eigen-analysis",
        )
    }
}

/// Refuse a lumped model whose analyses would not fit the memory this
/// process may take ([`analysis_bytes`]), before anything is sized from
/// its dof count.
pub fn check_model_memory(dofs: usize, nonzeros: usize) -> Result<(), crate::error::InputError> {
    let (need, what) = analysis_bytes(dofs, nonzeros);
    if need > MEMORY_CHECK_FROM {
        check(need, &format!("a lumped model of {dofs} dofs ({what})"))
            .map_err(crate::error::InputError)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn proc_lines_read_in_bytes() {
        let t = "Name:\tx\nVmSize:\t  2048 kB\nVmRSS:\t 10 kB\n";
        assert_eq!(proc_kb(t, "VmSize"), Some(2048.0 * 1024.0));
        assert_eq!(proc_kb(t, "VmData"), None);
    }

    #[test]
    fn the_machine_has_some_headroom_and_no_more_than_exists() {
        let h = headroom().expect("Linux reports MemAvailable");
        assert!(h.bytes > 0.0);
        assert!(check(1e18, "an exabyte").is_err());
        assert!(check(1.0, "a byte").is_ok());
    }
}
