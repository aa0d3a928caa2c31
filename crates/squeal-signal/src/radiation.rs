//! How loud: the equivalent radiated power of vibrating surfaces and the
//! sound pressure it makes at a distance, unweighted and A-weighted
//! (docs/physics.md §5f).
//!
//! **Equivalent radiated power** (ERP): a surface of area `Aᵢ` whose normal
//! velocity is `vᵢ(t)` radiates at most `ρc·Aᵢ·⟨vᵢ²⟩` (radiation efficiency
//! 1, the plane-wave limit reached above the coincidence frequency); the
//! surfaces' powers add (they are taken incoherent):
//!
//! ```text
//! W = ρc · Σᵢ Aᵢ ⟨vᵢ²⟩,        L_W = 10 log10(W / 1 pW)
//! ```
//!
//! **Sound pressure** at a distance `r` in the far field of a compact source
//! radiating `W` into the solid angle `Ω` (4π: free field, a full sphere;
//! 2π: a half-space over a reflecting plane): the intensity is `W/(Ω r²)` and
//! `p_rms² = ρc·W/(Ω r²)`, so `L_p = 10 log10(p_rms² / (20 µPa)²)`.
//!
//! **A-weighting** (IEC 61672-1:2013, Annex E, eq. E.6): each line of the
//! velocity's spectrum is weighted by `10^(A(f)/10)` before the power is
//! summed. The spectrum is the DFT of the whole stretch (rectangular window),
//! one-sided, scaled so that its lines add up to `⟨v²⟩` exactly
//! (Parseval): the unweighted level from the spectrum is the time-domain one.

use realfft::RealFftPlanner;

/// Reference sound pressure (Pa): 20 µPa.
pub const P_REF: f64 = 20e-6;

/// Reference sound power (W): 1 pW.
pub const W_REF: f64 = 1e-12;

/// Density of air at 20 °C and 101.325 kPa (kg/m³).
pub const RHO_AIR: f64 = 1.204;

/// Speed of sound in air at 20 °C (m/s).
pub const C_AIR: f64 = 343.2;

/// The A-weighting (dB) at `f` Hz, IEC 61672-1:2013 eq. (E.6):
/// `A(f) = 20 log10(f₄² f⁴ / ((f² + f₁²) √(f² + f₂²) √(f² + f₃²) (f² + f₄²))) − A₁₀₀₀`
/// with `f₁ = 20.60 Hz`, `f₂ = 107.7 Hz`, `f₃ = 737.9 Hz`, `f₄ = 12194 Hz`
/// and `A₁₀₀₀ = −2.000 dB` (so that `A(1 kHz) = 0`). `−∞` at 0 Hz.
pub fn a_weighting_db(f: f64) -> f64 {
    const F1: f64 = 20.598_997;
    const F2: f64 = 107.652_65;
    const F3: f64 = 737.862_23;
    const F4: f64 = 12_194.217;
    const A1000: f64 = -2.000;
    if f <= 0.0 {
        return f64::NEG_INFINITY;
    }
    let f2 = f * f;
    let r = F4 * F4 * f2 * f2
        / ((f2 + F1 * F1) * (f2 + F2 * F2).sqrt() * (f2 + F3 * F3).sqrt() * (f2 + F4 * F4));
    20.0 * r.log10() - A1000
}

/// The mean square `⟨v²⟩` of `v` and its A-weighted counterpart
/// `Σ_k P_k 10^(A(f_k)/10)` over the one-sided DFT power `P_k` of `v`
/// sampled at `fs` Hz (`Σ_k P_k = ⟨v²⟩`). `(0, 0)` for an empty signal.
pub fn mean_squares(v: &[f64], fs: f64) -> (f64, f64) {
    let n = v.len();
    if n == 0 {
        return (0.0, 0.0);
    }
    let plain = v.iter().map(|x| x * x).sum::<f64>() / n as f64;
    let mut planner = RealFftPlanner::<f64>::new();
    let fft = planner.plan_fft_forward(n);
    let mut input = v.to_vec();
    let mut spectrum = fft.make_output_vec();
    if fft.process(&mut input, &mut spectrum).is_err() {
        return (plain, f64::NAN);
    }
    let norm = 1.0 / (n as f64 * n as f64);
    let mut weighted = 0.0;
    for (k, x) in spectrum.iter().enumerate() {
        // Lines other than 0 and (for even n) n/2 stand for two of the
        // two-sided spectrum.
        let two_sided = if k == 0 || (n % 2 == 0 && k == n / 2) {
            1.0
        } else {
            2.0
        };
        let p = two_sided * x.norm_sqr() * norm;
        let f = k as f64 * fs / n as f64;
        if f > 0.0 {
            weighted += p * 10f64.powf(a_weighting_db(f) / 10.0);
        }
    }
    (plain, weighted)
}

/// Where the sound goes: the solid angle the power spreads into.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Space {
    /// A full sphere, 4π (free field).
    Free,
    /// A half-space over a reflecting plane, 2π.
    Half,
}

impl Space {
    /// `free` or `half`.
    pub fn as_str(self) -> &'static str {
        match self {
            Space::Free => "free",
            Space::Half => "half",
        }
    }
    /// `free` or `half`.
    pub fn parse(s: &str) -> Option<Space> {
        match s {
            "free" => Some(Space::Free),
            "half" => Some(Space::Half),
            _ => None,
        }
    }
    /// The solid angle Ω (sr).
    pub fn solid_angle(self) -> f64 {
        match self {
            Space::Free => 2.0 * std::f64::consts::TAU,
            Space::Half => std::f64::consts::TAU,
        }
    }
}

/// The levels of a set of radiating surfaces.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Levels {
    /// Equivalent radiated power `W` (W).
    pub erp_w: f64,
    /// `10 log10(W / 1 pW)` (dB).
    pub erp_db: f64,
    /// A-weighted ERP (W).
    pub erp_a_w: f64,
    /// Sound pressure level at the distance (dB re 20 µPa).
    pub spl_db: f64,
    /// A-weighted sound pressure level at the distance (dB(A) re 20 µPa).
    pub spl_dba: f64,
}

/// The medium and the listener: `ρ` (kg/m³), `c` (m/s), the distance `r`
/// (m) and the space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Listener {
    /// Density (kg/m³).
    pub rho: f64,
    /// Speed of sound (m/s).
    pub c: f64,
    /// Distance from the source (m).
    pub distance_m: f64,
    /// Free field or half-space.
    pub space: Space,
}

impl Listener {
    /// The sound pressure level (dB re 20 µPa) of a power `w` (W) at this listener:
    /// `10 log10(ρc·W/(Ω r²) / p_ref²)`.
    pub fn spl_db(&self, w: f64) -> f64 {
        let p2 = self.rho * self.c * w / (self.space.solid_angle() * self.distance_m.powi(2));
        10.0 * (p2 / (P_REF * P_REF)).log10()
    }

    /// The levels of `surfaces` — each an area (m²) and its normal velocity
    /// (m/s) sampled at `fs` Hz — by the module's equations.
    pub fn levels(&self, surfaces: &[(f64, &[f64])], fs: f64) -> Levels {
        let rho_c = self.rho * self.c;
        let (mut w, mut wa) = (0.0, 0.0);
        for (area, v) in surfaces {
            let (plain, weighted) = mean_squares(v, fs);
            w += rho_c * area * plain;
            wa += rho_c * area * weighted;
        }
        Levels {
            erp_w: w,
            erp_db: 10.0 * (w / W_REF).log10(),
            erp_a_w: wa,
            spl_db: self.spl_db(w),
            spl_dba: self.spl_db(wa),
        }
    }
}
