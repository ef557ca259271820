//! Unit tests of `gap::waveform`.

use nalgebra::{DMatrix, DVector};
use robot_survey::gap::waveform::{
    COEFFICIENTS, CycleBasis, LogSample, MIN_SAMPLES_PER_CYCLE, Signal, evaluate, parse_log,
    signature,
};

fn log_of_fn(f: impl Fn(f64) -> f64, hz: f64, cycles: f64, per_cycle: usize) -> Vec<LogSample> {
    let n = (cycles * per_cycle as f64) as usize;
    (0..n)
        .map(|i| {
            let t = i as f64 / (per_cycle as f64 * hz);
            LogSample {
                t_s: t,
                hip_angle_deg: f(t),
                roll_deg: 0.5 * f(t),
                pitch_deg: 1.0,
                yaw_deg: 3.0 * t + (std::f64::consts::TAU * hz * t).sin(),
                hip_torque_nm: None,
                drive_phase_cycles: None,
            }
        })
        .collect()
}

/// `log` with white Gaussian noise of sd `sd_deg` on every angle: Box–Muller on ChaCha8,
/// drawn hip, roll, pitch, yaw for each sample, the sequence `synth::add_sensor_noise`
/// makes for a log without torque. Made here so that these tests name no file above this
/// one (synth uses waveform, not the other way).
fn with_white_noise(log: &[LogSample], sd_deg: f64, seed: u64) -> Vec<LogSample> {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut n = || {
        let u1: f64 = 1.0 - rng.random::<f64>();
        let u2: f64 = rng.random::<f64>();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    };
    log.iter()
        .map(|s| LogSample {
            hip_angle_deg: s.hip_angle_deg + sd_deg * n(),
            roll_deg: s.roll_deg + sd_deg * n(),
            pitch_deg: s.pitch_deg + sd_deg * n(),
            yaw_deg: s.yaw_deg + sd_deg * n(),
            ..*s
        })
        .collect()
}

/// A known waveform: y = 2 + 10 sin 2πft + 3 cos 4πft − 1 sin 6πft + ½ cos 20πft gives
/// a₀ = 2, b₁ = 10, a₂ = 3, b₃ = −1, a₁₀ = ½ and nothing else, exactly (the tenth
/// harmonic: the short features of backlash and latency live that high); yaw's linear
/// drift is removed and its sin term kept; a constant has RMS 0.
#[test]
fn harmonics_of_a_known_waveform() {
    let hz = 1.7;
    let tau = std::f64::consts::TAU;
    let f = |t: f64| {
        2.0 + 10.0 * (tau * hz * t).sin() + 3.0 * (2.0 * tau * hz * t).cos()
            - (3.0 * tau * hz * t).sin()
            + 0.5 * (10.0 * tau * hz * t).cos()
    };
    let log = log_of_fn(f, hz, 12.3, 150);
    let sig = signature(&log, hz, 2).expect("signature");
    assert_eq!(sig.cycles, 10, "cycles 2..=11; the cut 12th is dropped");
    let hip = sig.signal(Signal::HipAngle).expect("hip");
    // [a₀, a₁, b₁, a₂, b₂, …]: a_h at 2h − 1, b_h at 2h.
    let mut want = vec![0.0; COEFFICIENTS];
    (want[0], want[2], want[3], want[6], want[19]) = (2.0, 10.0, 3.0, -1.0, 0.5);
    assert_eq!(hip.coefficients.len(), want.len());
    for (c, w) in hip.coefficients.iter().zip(&want) {
        assert!((c - w).abs() < 1e-9, "{:?} vs {want:?}", hip.coefficients);
    }
    // RMS of the AC part: √((10² + 3² + 1² + ½²)/2).
    assert!((hip.rms - (110.25f64 / 2.0).sqrt()).abs() < 1e-9);
    let yaw = sig.signal(Signal::Yaw).expect("yaw");
    assert!(yaw.coefficients[0].is_nan());
    assert!(
        (yaw.coefficients[2] - 1.0).abs() < 1e-9,
        "{:?}",
        yaw.coefficients
    );
    let pitch = sig.signal(Signal::Pitch).expect("pitch");
    assert!((pitch.coefficients[0] - 1.0).abs() < 1e-12 && pitch.rms < 1e-9);
    assert!(sig.signal(Signal::HipTorque).is_none(), "no torque column");
    // The rebuilt cycle at phase ¼: 2 + 10 − 3 + 1 + ½·cos 5π = 9.5.
    assert!((evaluate(&hip.coefficients, 0.25) - 9.5).abs() < 1e-9);
}

/// The drive phase column wins over f·t: a log whose clock starts 0.25 cycle late but
/// carries the phase gives the same coefficients as the aligned one.
#[test]
fn drive_phase_column_aligns_a_late_clock() {
    let hz = 2.0;
    let tau = std::f64::consts::TAU;
    let f = |t: f64| 5.0 * (tau * hz * t).sin();
    let aligned = log_of_fn(f, hz, 10.0, 100);
    let late: Vec<LogSample> = aligned
        .iter()
        .map(|s| LogSample {
            drive_phase_cycles: Some(s.t_s * hz),
            t_s: s.t_s + 0.125,
            ..*s
        })
        .collect();
    let a = signature(&aligned, hz, 1).expect("a");
    let b = signature(&late, hz, 1).expect("b");
    let (ha, hb) = (
        a.signal(Signal::HipAngle).unwrap(),
        b.signal(Signal::HipAngle).unwrap(),
    );
    for (x, y) in ha.coefficients.iter().zip(&hb.coefficients) {
        assert!((x - y).abs() < 1e-9);
    }
}

/// White noise of sd σ on N samples per cycle gives a harmonic coefficient a spread of
/// σ·√(2/N) (least squares on an orthogonal basis); checked over 60 cycles to 25 %.
#[test]
fn spread_of_white_noise_matches_least_squares_theory() {
    let hz = 1.0;
    let clean = log_of_fn(|t| (std::f64::consts::TAU * t).sin(), hz, 63.0, 200);
    let noisy = with_white_noise(&clean, 0.4, 7);
    let sig = signature(&noisy, hz, 2).expect("sig");
    let hip = sig.signal(Signal::HipAngle).unwrap();
    let want = 0.4 * (2.0f64 / 200.0).sqrt();
    for c in 1..hip.spread.len() {
        assert!(
            (hip.spread[c] / want - 1.0).abs() < 0.25,
            "coefficient {c}: spread {} vs {want}",
            hip.spread[c]
        );
    }
}

/// The factored normal equations against an independent solver: on an irregularly
/// sampled stretch of a cycle (phases 0.05–0.95, jittered; 40 samples) of an arbitrary
/// signal, with and without the trend column, the coefficients equal nalgebra's SVD
/// least squares of the same design matrix (built here with direct cos/sin).
#[test]
fn cycle_fit_equals_svd_least_squares_on_irregular_samples() {
    let phases: Vec<f64> = (0..40)
        .map(|i| 0.05 + 0.9 * (i as f64 + 0.37 * ((i * 7 % 5) as f64 / 5.0)) / 40.0)
        .collect();
    let y: Vec<f64> = phases
        .iter()
        .map(|p| (3.0 * p).exp() + (17.0 * p).sin() + if *p > 0.6 { 1.5 } else { 0.0 })
        .collect();
    let basis = CycleBasis::new(phases.iter().copied());
    let k = COEFFICIENTS;
    for trend in [false, true] {
        let cols = k + usize::from(trend);
        let a = DMatrix::from_fn(phases.len(), cols, |r, c| {
            let phi = phases[r];
            if c == 0 {
                1.0
            } else if c < k {
                let x = std::f64::consts::TAU * c.div_ceil(2) as f64 * phi;
                if c % 2 == 1 { x.cos() } else { x.sin() }
            } else {
                phi - 0.5
            }
        });
        let want = a
            .svd(true, true)
            .solve(&DVector::from_column_slice(&y), 1e-12)
            .expect("svd");
        let got = basis.fit(&y, trend).expect("fit");
        assert_eq!(got.len(), k);
        for (g, w) in got.iter().zip(want.iter()) {
            assert!(
                (g - w).abs() < 1e-7 * (1.0 + w.abs()),
                "{got:?} vs {want:?}"
            );
        }
    }
}

/// A log too coarse for the harmonics kept is refused with the number it needs: 30
/// samples per cycle against 2·12 + 8 = 32.
#[test]
fn a_log_sampled_below_the_harmonics_needs_is_refused() {
    assert_eq!(MIN_SAMPLES_PER_CYCLE, 32);
    let log = log_of_fn(|t| t.sin(), 1.0, 10.0, 30);
    let e = signature(&log, 1.0, 2).expect_err("30 per cycle");
    assert!(e.contains("at least 32 samples"), "{e}");
    assert!(signature(&log_of_fn(|t| t.sin(), 1.0, 10.0, 32), 1.0, 2).is_ok());
}

#[test]
fn too_few_cycles_and_bad_logs_are_clear_errors() {
    let log = log_of_fn(|t| t.sin(), 1.0, 4.0, 50);
    let e = signature(&log, 1.0, 2).expect_err("2 cycles");
    assert!(e.contains("at least 3"), "{e}");
    let e = parse_log("t_s,roll_deg,pitch_deg,yaw_deg\n0,0,0,0\n", "x.csv").expect_err("hip");
    assert!(
        e.to_string().contains("missing column `hip_angle_deg`"),
        "{e}"
    );
    let e = parse_log(
        "t_s,hip_angle_deg,roll_deg,pitch_deg,yaw_deg\n0,1,2,3,4\n0.01,1,two,3,4\n",
        "x.csv",
    )
    .expect_err("number");
    assert!(e.to_string().starts_with("x.csv:3:3:"), "{e}");
    let e = parse_log(
        "t_s,hip_angle_deg,roll_deg,pitch_deg,yaw_deg\n0.1,1,2,3,4\n0.1,1,2,3,4\n",
        "x.csv",
    )
    .expect_err("time");
    assert!(e.to_string().contains("does not increase"), "{e}");
    let ok = parse_log(
        "# a comment\nyaw_deg,t_s,pitch_deg,roll_deg,hip_angle_deg,extra\n4,0,3,2,1,x\n",
        "x.csv",
    )
    .expect("any order, extra columns");
    assert_eq!(ok[0].hip_angle_deg, 1.0);
    assert_eq!(ok[0].yaw_deg, 4.0);
    assert!(ok[0].hip_torque_nm.is_none());
}
