//! Issue 24, classes 7 and 8, against the real binary: messages name the
//! real cause (a bad mass, not dependent tangents; a limit with its value),
//! and user-raised limits still end in bounded time.

use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_squeal");

fn within(dir: &Path, args: &[&str], limit: Duration) -> Output {
    let mut child = Command::new(BIN)
        .current_dir(dir)
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > limit {
            let _ = child.kill();
            panic!("{args:?} still running after {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

fn refused(o: &Output, needles: &[&str]) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "exit 2 expected: {err}");
    for n in needles {
        assert!(err.contains(n), "{n:?} not in: {err}");
    }
}

#[test]
fn an_extreme_mass_is_reported_as_a_bad_mass() {
    let d = tempfile::tempdir().unwrap();
    let quick = Duration::from_secs(20);
    // Today: "contact 'pad2': tangent: its stick constraint is redundant
    // with 'pad1' (the tangents are linearly dependent …)", and the value
    // printed with 301 digits.
    let o = within(
        d.path(),
        &[
            "stability",
            "two-pad-brake",
            "--set",
            "mass.x_p1=1e300",
            "--set",
            "mass.x_p2=1e300",
        ],
        quick,
    );
    refused(
        &o,
        &[
            "mass.x_p1 = 1e300",
            "a mass must be a number from 1e-30 to 1e30",
        ],
    );
    assert!(!String::from_utf8_lossy(&o.stderr).contains("000000000000"));
    let o = within(
        d.path(),
        &["stability", "two-pad-brake", "--set", "mass.x_p1=1e-300"],
        quick,
    );
    refused(&o, &["mass.x_p1 = 1e-300", "a mass must be"]);
    // Within the range but 1e26 times the pads' other masses: the masses
    // are named as the cause, not the tangents.
    let o = within(
        d.path(),
        &[
            "stability",
            "two-pad-brake",
            "--set",
            "mass.x_p1=1e25",
            "--set",
            "mass.x_p2=1e25",
        ],
        quick,
    );
    refused(
        &o,
        &[
            "mass.x_p2 = 1e25: a bad mass",
            "the tangents themselves are independent",
        ],
    );
    assert!(!String::from_utf8_lossy(&o.stderr).contains("redundant"));
    // The same in a model file's [masses].
    let o = within(d.path(), &["scenario", "show", "two-pad-brake"], quick);
    let text = String::from_utf8_lossy(&o.stdout).replace("x_p1 = 0.1", "x_p1 = 1e300");
    std::fs::write(d.path().join("heavy.toml"), text).unwrap();
    let o = within(d.path(), &["stability", "heavy.toml"], quick);
    refused(
        &o,
        &[
            "masses: x_p1 = 1e300",
            "a mass must be a number from 1e-30 to 1e30",
        ],
    );
}

#[test]
fn a_single_contact_is_never_redundant_with_others() {
    let d = tempfile::tempdir().unwrap();
    // One contact whose tangent moves a dof of no mass the model can
    // resolve: t·M⁻¹·t underflows to 0.
    let text = r#"name = "one"
model = "lumped"
dofs = ["x", "y"]

[masses]
x = 1e30
y = 1.0

[[spring]]
name = "kx"
on = { x = 1.0 }
k = 1e3

[[spring]]
name = "ky"
on = { y = 1.0 }
k = 1e3

[[force]]
name = "load"
on = { y = 1.0 }
value = 10.0

[[contact]]
name = "only"
normal = { y = 1.0 }
k = 1e5
tangent = { x = 1e-150 }
V = 1.0
friction = "coulomb"
mu_s = 0.5
mu_k = 0.4
"#;
    std::fs::write(d.path().join("one.toml"), text).unwrap();
    let o = within(
        d.path(),
        &["stability", "one.toml"],
        Duration::from_secs(20),
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(!err.contains("other contacts"), "{err}");
    assert!(
        err.contains("mass.x = 1e30: a bad mass") && err.contains("contact 'only'"),
        "{err}"
    );
}

#[test]
fn every_limit_is_named_with_its_value() {
    let d = tempfile::tempdir().unwrap();
    let quick = Duration::from_secs(20);
    let o = within(
        d.path(),
        &[
            "branch",
            "disc-pad",
            "--param",
            "V=1:13:100000000",
            "--out",
            "b",
        ],
        quick,
    );
    refused(&o, &["N = 100000000", "from 2 to 10000 grid values"]);
    let o = within(
        d.path(),
        &["map", "--x", "V=1:13:100000", "--y", "N=1:2:2"],
        quick,
    );
    refused(&o, &["V=1:13:100000", "between 2 and 4000"]);
    let o = within(d.path(), &["simulate", "--set", "sample_rate=1e12"], quick);
    refused(&o, &["5.000e11 samples", "limit of 5e7 samples"]);
    let o = within(
        d.path(),
        &["critical", "--param", "V=0.1:10", "--grid", "1000000"],
        quick,
    );
    refused(&o, &["--grid 1000000", "between 2 and 100000"]);
}

#[test]
fn raised_settling_limits_still_end_in_bounded_time() {
    let d = tempfile::tempdir().unwrap();
    let quick = Duration::from_secs(20);
    // Today: with these, `cycle` runs without end.
    let o = within(
        d.path(),
        &[
            "cycle",
            "disc-pad",
            "--settle-steps",
            "18446744073709551615",
            "--settle-time",
            "1e300",
        ],
        quick,
    );
    refused(
        &o,
        &["--settle-steps 18446744073709551615", "1000000000 steps"],
    );
    let o = within(
        d.path(),
        &["cycle", "disc-pad", "--settle-tol", "1e-300"],
        quick,
    );
    refused(&o, &["--settle-tol 1e-300", "below 1e-9"]);
    // The largest accepted values: a motion that never settles (steady
    // sliding of a stable belt) ends when its step budget is spent,
    // naming the time and steps.
    let o = within(
        d.path(),
        &[
            "cycle",
            "belt",
            "--set",
            "V=100",
            "--settle-steps",
            "200000",
            "--settle-time",
            "1e300",
        ],
        Duration::from_secs(60),
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert_ne!(o.status.code(), Some(0), "{err}");
    assert!(
        err.contains("steps") || err.contains("does not oscillate"),
        "{err}"
    );
}
