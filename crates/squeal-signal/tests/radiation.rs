//! Radiated power and sound levels against hand-computed values.

use squeal_signal::radiation::{C_AIR, P_REF, RHO_AIR, W_REF};
use squeal_signal::{a_weighting_db, mean_squares, Listener, Space};
use std::f64::consts::{PI, TAU};

/// IEC 61672-1:2013 Table 3's A-weightings (dB, given to 0.1 dB) at the
/// exact base-10 third-octave frequencies `1000·10^(k/10)` Hz (nominally
/// 31.5 Hz … 16 kHz): the formula must round to them.
#[test]
fn a_weighting_matches_the_standards_table() {
    let table = [
        (-15, -39.4),
        (-12, -26.2),
        (-10, -19.1),
        (-6, -8.6),
        (-3, -3.2),
        (0, 0.0),
        (3, 1.2),
        (6, 1.0),
        (9, -1.1),
        (10, -2.5),
        (12, -6.6),
    ];
    for (k, a) in table {
        let f = 1000.0 * 10f64.powf(k as f64 / 10.0);
        let got = a_weighting_db(f);
        assert!(
            (got - a).abs() <= 0.05,
            "A({f:.1} Hz) = {got:.3} dB, table {a}"
        );
    }
    assert!(a_weighting_db(1000.0).abs() < 1e-3);
    assert_eq!(a_weighting_db(0.0), f64::NEG_INFINITY);
}

/// A sine of amplitude `a` with a whole number of periods: ⟨v²⟩ = a²/2
/// exactly, and its one DFT line carries it all, so the A-weighted mean
/// square is ⟨v²⟩·10^(A(f)/10).
#[test]
fn a_sine_has_its_mean_square_on_one_weighted_line() {
    let (fs, f, a) = (48_000.0, 2000.0, 3e-3);
    let n = 4800; // 200 periods
    let v: Vec<f64> = (0..n)
        .map(|i| a * (TAU * f * i as f64 / fs).sin())
        .collect();
    let (plain, weighted) = mean_squares(&v, fs);
    assert!((plain / (a * a / 2.0) - 1.0).abs() < 1e-12, "{plain}");
    let expect = a * a / 2.0 * 10f64.powf(a_weighting_db(f) / 10.0);
    assert!(
        (weighted / expect - 1.0).abs() < 1e-10,
        "{weighted} vs {expect}"
    );
}

/// Parseval, line by line: a mean (0 Hz, weight 0), a tone on a bin and a
/// tone at the Nyquist line (even length, a line counted once) give
/// exactly their own powers, each weighted at its frequency.
#[test]
fn each_line_carries_its_own_power() {
    let (fs, n) = (10_000.0, 1000);
    let (dc, b, c) = (0.3, 0.7, 0.2);
    let v: Vec<f64> = (0..n)
        .map(|i| {
            let t = i as f64 / fs;
            dc + b * (TAU * 1230.0 * t + 0.4).cos() + c * if i % 2 == 0 { 1.0 } else { -1.0 }
        })
        .collect();
    let (plain, weighted) = mean_squares(&v, fs);
    let expect_plain = dc * dc + b * b / 2.0 + c * c;
    assert!(
        (plain - expect_plain).abs() < 1e-12,
        "{plain} vs {expect_plain}"
    );
    let g = |f: f64| 10f64.powf(a_weighting_db(f) / 10.0);
    let expect = b * b / 2.0 * g(1230.0) + c * c * g(fs / 2.0);
    assert!(
        (weighted / expect - 1.0).abs() < 1e-10,
        "{weighted} vs {expect}"
    );
}

/// ERP, SPL and SPL(A) of a piston by hand: W = ρc·A·a²/2,
/// p² = ρc·W/(4πr²) (free) or /(2πr²) (half-space).
#[test]
fn levels_of_a_sine_piston_by_hand() {
    let (fs, f, a, area, r) = (40_000.0, 1000.0, 1e-3, 0.05, 2.0);
    let v: Vec<f64> = (0..4000)
        .map(|i| a * (TAU * f * i as f64 / fs).sin())
        .collect();
    let free = Listener {
        rho: RHO_AIR,
        c: C_AIR,
        distance_m: r,
        space: Space::Free,
    };
    let l = free.levels(&[(area, &v)], fs);
    let w = RHO_AIR * C_AIR * area * a * a / 2.0;
    assert!((l.erp_w / w - 1.0).abs() < 1e-12);
    assert!((l.erp_db - 10.0 * (w / W_REF).log10()).abs() < 1e-9);
    // By hand: ρc = 413.2 Pa·s/m, W = 1.0330e-5 W → 70.14 dB re 1 pW;
    // p² = 413.2 · 1.0330e-5 / (4π · 4) = 8.492e-5 Pa² → 53.27 dB.
    assert!((l.erp_db - 70.141).abs() < 1e-3, "{}", l.erp_db);
    let p2 = RHO_AIR * C_AIR * w / (4.0 * PI * r * r);
    assert!((l.spl_db - 10.0 * (p2 / (P_REF * P_REF)).log10()).abs() < 1e-9);
    assert!((l.spl_db - 53.2696).abs() < 1e-3, "{}", l.spl_db);
    // At 1 kHz the A-weighting is 0 dB.
    assert!((l.spl_dba - l.spl_db).abs() < 1e-3);
    let half = Listener {
        space: Space::Half,
        ..free
    };
    let h = half.levels(&[(area, &v)], fs);
    assert!((h.spl_db - l.spl_db - 10.0 * 2f64.log10()).abs() < 1e-9);
    // Two equal surfaces radiate twice the power: +3.01 dB.
    let two = free.levels(&[(area, &v), (area, &v)], fs);
    assert!((two.erp_db - l.erp_db - 10.0 * 2f64.log10()).abs() < 1e-9);
}
