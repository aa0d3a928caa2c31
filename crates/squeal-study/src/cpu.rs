//! Whether this processor can run this build: the workspace builds for
//! x86-64-v3 by default (`.cargo/config.toml`), and such a binary on a
//! processor without AVX2 would die of an illegal instruction at some later
//! point; the command line and the Python package ask first and refuse in
//! one line.

/// The first instruction-set extension this build was compiled for that the
/// processor lacks (`None`: it has all of them, or the build needs none).
/// Only the extensions of x86-64-v2 and v3 are checked.
pub fn missing_feature() -> Option<&'static str> {
    #[cfg(target_arch = "x86_64")]
    {
        macro_rules! need {
            ($($f:tt),*) => {$(
                #[cfg(target_feature = $f)]
                if !std::arch::is_x86_feature_detected!($f) {
                    return Some($f);
                }
            )*};
        }
        need!(
            "sse3",
            "ssse3",
            "sse4.1",
            "sse4.2",
            "popcnt",
            "cmpxchg16b",
            "avx",
            "avx2",
            "bmi1",
            "bmi2",
            "f16c",
            "fma",
            "lzcnt",
            "movbe",
            "xsave"
        );
    }
    None
}

/// The one line that refuses to run on a processor lacking `feature`.
pub fn refusal(feature: &str) -> String {
    format!(
        "this squeal was built for x86-64-v3 (AVX2, FMA; .cargo/config.toml) and this processor \
         lacks {feature}: rebuild it with `RUSTFLAGS= cargo build --release`"
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The machine that built and runs the tests has what the build needs
    /// (else the test binary could not have run this far), and the refusal
    /// names the missing extension and the way out.
    #[test]
    fn this_processor_runs_this_build() {
        assert_eq!(missing_feature(), None);
        let line = refusal("avx2");
        assert!(line.contains("lacks avx2") && line.contains("RUSTFLAGS="));
        assert!(!line.contains('\n'));
    }
}
