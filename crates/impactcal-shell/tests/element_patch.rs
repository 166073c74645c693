//! V1 (rigid motion of a warped element, constant membrane and bending patches), V3
//! (stability limit), conservation of momentum and thread-count independence.

#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::float_cmp,
    clippy::needless_range_loop
)]

mod common;

use common::*;
use impactcal_shell::element::{self, KernelOptions, PartProps, STATE_HEAD, STATE_PER_POINT};
use impactcal_shell::{
    Hourglass, InitialVelocity, Section, ShellError, Simulation, VelocityTarget,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn props(t: f64, nip: usize) -> PartProps {
    let mut section = Section::new(1, t);
    section.nip = nip;
    PartProps::new(&section, &aluminium(1), &Hourglass::default()).unwrap()
}

fn rotation(axis: [f64; 3], angle: f64) -> [[f64; 3]; 3] {
    let n = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
    let [x, y, z] = [axis[0] / n, axis[1] / n, axis[2] / n];
    let (s, c) = angle.sin_cos();
    let k = 1.0 - c;
    [
        [c + x * x * k, x * y * k - z * s, x * z * k + y * s],
        [y * x * k + z * s, c + y * y * k, y * z * k - x * s],
        [z * x * k - y * s, z * y * k + x * s, c + z * z * k],
    ]
}

fn apply(r: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|i| r[i][0] * v[0] + r[i][1] * v[1] + r[i][2] * v[2])
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Max |stress| over the points and max |force| after rotating a warped, distorted quad by
/// 90 degrees about a skew axis in 10^4 increments while translating it.
fn rigid_rotation_residual(projection: bool) -> (f64, f64) {
    let x0 = [
        [0.0, 0.0, 0.0],
        [1.1, 0.1, 0.06],
        [1.0, 0.9, -0.05],
        [-0.1, 1.2, 0.07],
    ]
    .map(|p| p.map(|c| 0.1 * c));
    let p = props(0.002, 5);
    let mut st = vec![0.0; STATE_HEAD + 5 * STATE_PER_POINT];
    let axis = [0.3, -0.5, 0.8];
    let n = (0.09f64 + 0.25 + 0.64).sqrt();
    let omega_rate = 200.0; // rad/s
    let om = axis.map(|c| c / n * omega_rate);
    let vt = [1.0, -2.0, 0.5];
    let steps = 10_000;
    let dt = std::f64::consts::FRAC_PI_2 / omega_rate / steps as f64;
    let mut fmax: f64 = 0.0;
    let opts = KernelOptions {
        projection,
        isdo_diagonal: false,
        invariant: false,
        distortion_check: true,
    };
    for k in 1..=steps {
        let t = k as f64 * dt;
        let r = rotation(axis, omega_rate * t);
        let c = vt.map(|v| v * t);
        let x = x0.map(|p| {
            let q = apply(&r, p);
            [q[0] + c[0], q[1] + c[1], q[2] + c[2]]
        });
        let v = x.map(|p| {
            let w = cross(om, [p[0] - c[0], p[1] - c[1], p[2] - c[2]]);
            [w[0] + vt[0], w[1] + vt[1], w[2] + vt[2]]
        });
        let out = element::quad(&x, &v, &[om; 4], &p, &mut st, dt, opts).unwrap();
        fmax = fmax.max(out.f.iter().flatten().fold(0.0, |a, b| a.max(b.abs())));
    }
    let smax = st.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    (smax, fmax)
}

#[test]
fn rigid_rotation_of_a_warped_quad_gives_no_strain_with_the_projection() {
    let (s, f) = rigid_rotation_residual(true);
    // Relative to the stress of a unit rotation-sized strain (E * 1 rad ~ 7e10 Pa).
    assert!(s / E < 1e-10, "stress {s:.3e} Pa");
    assert!(f < 1e-3, "force {f:.3e} N");
    // Without the projection the same motion strains the warped element.
    let (s_plain, _) = rigid_rotation_residual(false);
    assert!(
        s_plain / E > 1e-8 && s_plain > 1e3 * s,
        "stress without projection {s_plain:.3e}"
    );
}

/// Constant membrane strain rate on a distorted 2 x 2 patch: every element gets exactly
/// `C de` and the interior node is in equilibrium.
#[test]
fn constant_membrane_and_bending_patches_are_exact() {
    let xs = [
        [0.0, 0.0],
        [0.5, 0.0],
        [1.0, 0.0],
        [0.0, 0.5],
        [0.62, 0.41],
        [1.0, 0.5],
        [0.0, 1.0],
        [0.5, 1.0],
        [1.0, 1.0],
    ];
    let quads = [[0, 1, 4, 3], [1, 2, 5, 4], [3, 4, 7, 6], [4, 5, 8, 7]];
    let t = 0.01;
    let p = props(t, 5);
    let mat = p.material();
    let dt = 1e-6;
    // Membrane: v = L x with L = [[a, b], [c, d]].
    let (la, lb, lc, ld) = (3.0, 1.0, -2.0, 0.5);
    let mut interior = [0.0; 6];
    for q in quads {
        let x = q.map(|i| [xs[i][0], xs[i][1], 0.0]);
        let v = x.map(|p| [la * p[0] + lb * p[1], lc * p[0] + ld * p[1], 0.0]);
        let mut st = vec![0.0; STATE_HEAD + 5 * STATE_PER_POINT];
        let out = element::quad(
            &x,
            &v,
            &[[0.0; 3]; 4],
            &p,
            &mut st,
            dt,
            KernelOptions {
                projection: true,
                isdo_diagonal: false,
                invariant: false,
                distortion_check: true,
            },
        )
        .unwrap();
        let de = [la * dt, ld * dt, (lb + lc) * dt];
        let sxx = mat.c11 * (de[0] + mat.nu * de[1]);
        let syy = mat.c11 * (de[1] + mat.nu * de[0]);
        let sxy = mat.g * de[2];
        // Stresses are in the element frame: compare the in-plane invariants.
        for k in 0..5 {
            let s = &st[STATE_HEAD + STATE_PER_POINT * k..];
            assert!((s[0] + s[1] - sxx - syy).abs() < 1e-9 * sxx.abs());
            let det = s[0] * s[1] - s[2] * s[2];
            assert!((det - (sxx * syy - sxy * sxy)).abs() < 1e-9 * sxx * sxx);
        }
        let slot = q.iter().position(|&i| i == 4).unwrap();
        for d in 0..6 {
            interior[d] += out.f[slot][d];
        }
    }
    let scale = mat.c11 * 3.0 * dt * t * 0.5;
    assert!(
        interior.iter().all(|f| f.abs() < 1e-9 * scale),
        "{interior:?}"
    );

    // Bending: omega_y = kx x, omega_x = -ky y gives curvature rates (kx, ky); the moment
    // M = t sum w z s equals D (k + nu k) dt exactly with 5 Gauss points.
    let (kx, ky) = (2.0, 2.0);
    let d = mat.c11 * t * t * t / 12.0;
    for q in quads {
        let x = q.map(|i| [xs[i][0], xs[i][1], 0.0]);
        let w = x.map(|p| [-ky * p[1], kx * p[0], 0.0]);
        let mut st = vec![0.0; STATE_HEAD + 5 * STATE_PER_POINT];
        element::quad(
            &x,
            &[[0.0; 3]; 4],
            &w,
            &p,
            &mut st,
            dt,
            KernelOptions {
                projection: true,
                isdo_diagonal: false,
                invariant: false,
                distortion_check: true,
            },
        )
        .unwrap();
        // Equal curvatures in x and y: isotropic, so frame-independent.
        let (mut mxx, mut myy, mut nxx) = (0.0, 0.0, 0.0);
        for k in 0..5 {
            let s = &st[STATE_HEAD + STATE_PER_POINT * k..];
            mxx += t * p.weights()[k] * p.heights()[k] * s[0];
            myy += t * p.weights()[k] * p.heights()[k] * s[1];
            nxx += t * p.weights()[k] * s[0];
        }
        let exx = d * (kx + mat.nu * ky) * dt;
        let eyy = d * (ky + mat.nu * kx) * dt;
        assert!((mxx - exx).abs() < 1e-10 * exx.abs(), "{mxx} vs {exx}");
        assert!((myy - eyy).abs() < 1e-10 * exx.abs(), "{myy} vs {eyy}");
        assert!(nxx.abs() < 1e-10 * exx.abs() / t);
    }
}

fn random_plate(seed: u64, n: u64, warp: f64) -> impactcal_shell::ShellModel {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let h = 0.01;
    let mut m = plate(n, n, h * n as f64, h * n as f64, [0.0; 3]);
    with_section(&mut m, 0.001, aluminium(1));
    for p in m.nodes.iter_mut() {
        p.x[0] += rng.random_range(-0.15..0.15) * h;
        p.x[1] += rng.random_range(-0.15..0.15) * h;
        p.x[2] += rng.random_range(-1.0..1.0) * warp * h;
    }
    for p in m.nodes.clone() {
        let mut iv = InitialVelocity::translation(
            VelocityTarget::Node(p.id),
            [0.0; 3].map(|_: f64| rng.random_range(-1.0..1.0)),
        );
        iv.rotation = [0.0; 3].map(|_: f64| rng.random_range(-10.0..10.0));
        m.initial_velocities.push(iv);
    }
    m
}

/// V3: the estimated step is below the stability limit 2 / omega_max (power iteration);
/// a run at 0.9 x the limit stays stable, one at 1.2 x stops with a typed error.
#[test]
fn stable_below_and_unstable_above_the_critical_step() {
    let m = random_plate(7, 4, 0.05);
    let sim = Simulation::new(&m).unwrap();
    let w_max = sim.max_frequency(3000);
    let limit = 2.0 / w_max;
    let estimate = sim.dt() / 0.9;
    assert!(
        estimate <= limit,
        "estimated {estimate:.3e} > limit {limit:.3e}"
    );
    assert!(
        estimate > 0.3 * limit,
        "estimate {estimate:.3e} far below the limit {limit:.3e}"
    );

    let mut stable = m.clone();
    stable.control.fixed_dt = Some(0.9 * limit);
    stable.control.end_time = 3000.0 * 0.9 * limit;
    let mut sim = Simulation::new(&stable).unwrap();
    let vmax0 = sim
        .velocities()
        .iter()
        .flatten()
        .fold(0.0f64, |a, b| a.max(b.abs()));
    let r = sim.run().unwrap();
    assert!(r.summary.cycles >= 2999);
    let vmax = sim
        .velocities()
        .iter()
        .flatten()
        .fold(0.0f64, |a, b| a.max(b.abs()));
    assert!(vmax < 3.0 * vmax0, "velocities grew from {vmax0} to {vmax}");

    let mut unstable = m;
    unstable.control.fixed_dt = Some(1.2 * limit);
    unstable.control.end_time = 3000.0 * 1.2 * limit;
    match Simulation::new(&unstable).unwrap().run() {
        Err(ShellError::Unstable { element, cycle, .. }) => {
            assert!(element >= 1 && cycle < 3000);
        }
        other => panic!(
            "expected an instability, got {:?}",
            other.map(|r| r.summary)
        ),
    }
}

/// V13: free flight of a warped, distorted plate with random velocities conserves linear
/// momentum to round-off (element forces are self-equilibrated).
#[test]
fn free_flight_conserves_linear_momentum() {
    let m = random_plate(11, 5, 0.1);
    let mut sim = Simulation::new(&m).unwrap();
    let momentum = |s: &Simulation| {
        let mut p = [0.0; 3];
        for (v, m) in s.velocities().iter().zip(s.masses()) {
            for d in 0..3 {
                p[d] += m * v[d];
            }
        }
        p
    };
    let p0 = momentum(&sim);
    let mass: f64 = sim.masses().iter().sum();
    for _ in 0..2000 {
        sim.step().unwrap();
    }
    let p1 = momentum(&sim);
    for d in 0..3 {
        assert!(
            (p1[d] - p0[d]).abs() < 1e-12 * mass,
            "axis {d}: {} vs {}",
            p1[d],
            p0[d]
        );
    }
}

/// Results are bit-identical for 1, 2 and 3 threads.
#[test]
fn results_do_not_depend_on_the_thread_count() {
    let mut m = random_plate(3, 24, 0.02);
    m.control.end_time = 2e-4;
    m.output.history_nodes = vec![1, 100, 300];
    m.output.interval = 1e-5;
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| Simulation::new(&m).unwrap().run().unwrap())
    };
    let a = run(1);
    for threads in [2, 3] {
        let b = run(threads);
        assert_eq!(
            a.velocity.as_ref().unwrap().data(),
            b.velocity.as_ref().unwrap().data()
        );
        assert_eq!(a.energies.data(), b.energies.data());
    }
}

/// The internal energy over the kinetic energy after a warped, distorted plate read from
/// `deck` has spun rigidly about an in-plane axis through 0.01 rad.
fn strain_of_a_rigid_spin(deck: &str) -> f64 {
    let mut m = impactcal_shell::keyword::parse_deck(deck, "warped.k")
        .unwrap()
        .model;
    let c = m.nodes.iter().fold([0.0; 3], |a, p| {
        [0, 1, 2].map(|k| a[k] + p.x[k] / m.nodes.len() as f64)
    });
    let mut spin = InitialVelocity::translation(VelocityTarget::All, [0.0; 3]);
    spin.omega = 50.0;
    spin.centre = c;
    spin.axis = [0.6, 0.8, 0.0];
    m.initial_velocities = vec![spin];
    m.control.end_time = 1.0;
    let mut sim = Simulation::new(&m).unwrap();
    while sim.time() < 0.01 / 50.0 {
        sim.step().unwrap();
    }
    let e = sim.energies();
    e.internal / e.kinetic
}

/// `*CONTROL_SHELL` BWC 1 with PROJ 1 is the full projection: a warped plate read with it
/// spins rigidly without straining (to the second-order stretch of the central-difference
/// rotation); read without the keyword (BWC 2, LS-DYNA's Belytschko-Tsay shell without a
/// warping treatment) the same spin strains it; the drill projection is refused.
#[test]
fn control_shell_bwc_and_proj_choose_the_warping_projection() {
    let mut m = random_plate(5, 4, 0.15);
    m.initial_velocities.clear();
    // Card 1 alone (the distortion check has its own test).
    m.control.distortion_check = false;
    let projected = impactcal_shell::keyword::write_deck(&m).unwrap();
    assert!(projected.contains("*CONTROL_SHELL"));
    let read = |d: &str| {
        impactcal_shell::keyword::parse_deck(d, "warped.k")
            .unwrap()
            .model
            .control
            .warping_projection
    };
    assert!(read(&projected));
    let card = format!("{}{:>10}{:>10}{:>10}", " ".repeat(50), 1, 0, 1);
    assert!(projected.contains(&card));
    let plain = projected.replace(&format!("*CONTROL_SHELL\n{card}\n"), "");
    assert!(!plain.contains("*CONTROL_SHELL"));
    assert!(!read(&plain));
    let bwc2 = projected.replace(
        &card,
        &format!("{}{:>10}{:>10}{:>10}", " ".repeat(50), 2, 0, 1),
    );
    assert!(!read(&bwc2));

    let with = strain_of_a_rigid_spin(&projected);
    let without = strain_of_a_rigid_spin(&plain);
    eprintln!("internal / kinetic after the spin: projection {with:e}, none {without:e}");
    assert!(with < 1e-6, "projection on: internal / kinetic {with:e}");
    assert!(
        without > 100.0 * with,
        "projection off: {without:e} against {with:e}"
    );

    let drill = projected.replace(
        &card,
        &format!("{}{:>10}{:>10}{:>10}", " ".repeat(50), 1, 0, 0),
    );
    let err = impactcal_shell::keyword::parse_deck(&drill, "warped.k").unwrap_err();
    let msg = err.to_string();
    assert!(msg.contains("PROJ") && msg.contains("drill"), "{msg}");
}

/// The plain Belytschko-Tsay quad (no warping projection, LS-DYNA's BWC 2) under a rigid
/// rotation of a mildly warped quad, against its closed form. The element's strain rates
/// (membrane, curvature, transverse shear) never see the warp, so the section stresses stay
/// zero; only the two membrane hourglass rates do, through `gamma . z = 4 w`
/// (`w = h . z / 4`, `z` the corners' heights over the mean plane): a rotation `phi` about
/// an in-plane axis stores `E_hg = C_m (4 w phi)^2 / 2` with the stiffness-form coefficient
/// `C_m = r E t A (B . B) / 8 = r E t (|d31|^2 + |d42|^2) / (16 A)`, `A = |d31 x d42| / 2`.
/// The spurious energy therefore grows as the warp squared and with the hourglass
/// coefficient, and the full projection removes it.
#[test]
fn the_plain_element_strains_a_rotating_warped_quad_only_through_its_membrane_hourglass() {
    let t = 0.001;
    let p = props(t, 5);
    let a = 0.01;
    let phi = 0.01;
    let steps = 2000;
    let rate = 50.0;
    let dt = phi / rate / steps as f64;
    let mut last = None;
    for (case, eps) in [0.01, 0.02, 0.05].into_iter().enumerate() {
        // A distorted quad warped by eps of its size, about its centroid.
        let wz = eps * a;
        let x0 = [
            [0.0, 0.0, wz],
            [1.1 * a, 0.1 * a, -wz],
            [1.0 * a, 0.9 * a, wz],
            [-0.1 * a, 1.2 * a, -wz],
        ];
        let c: [f64; 3] = std::array::from_fn(|k| x0.iter().map(|q| q[k]).sum::<f64>() / 4.0);
        let x0 = x0.map(|q| [q[0] - c[0], q[1] - c[1], q[2] - c[2]]);
        // Closed form from the geometry alone.
        let sub = |i: usize, j: usize| [0, 1, 2].map(|k| x0[i][k] - x0[j][k]);
        let (d31, d42) = (sub(2, 0), sub(3, 1));
        let n = cross(d31, d42);
        let nn = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        let e3 = n.map(|c| c / nn);
        let area = 0.5 * nn;
        let w = [0, 1, 2]
            .map(|k| (x0[0][k] - x0[1][k] + x0[2][k] - x0[3][k]) * e3[k])
            .iter()
            .sum::<f64>()
            / 4.0;
        let sq = |d: [f64; 3]| d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        let cm = 0.05 * E * t * (sq(d31) + sq(d42)) / (16.0 * area);
        // The axis: in the element's plane, skewed.
        let axis = cross(e3, [0.3, 0.8, 0.5]);
        let predicted = 0.5 * cm * (4.0 * w * phi).powi(2);
        for projection in [false, true] {
            let opts = KernelOptions {
                projection,
                isdo_diagonal: false,
                invariant: false,
                distortion_check: true,
            };
            let an = sq(axis).sqrt();
            let om = axis.map(|c| c / an * rate);
            let mut st = vec![0.0; STATE_HEAD + 5 * STATE_PER_POINT];
            let (mut hourglass, mut internal) = (0.0, 0.0);
            for k in 1..=steps {
                let r = rotation(axis, rate * k as f64 * dt);
                let x = x0.map(|q| apply(&r, q));
                let v = x.map(|q| cross(om, q));
                let out = element::quad(&x, &v, &[om; 4], &p, &mut st, dt, opts).unwrap();
                hourglass += out.hourglass;
                internal += out.internal;
            }
            let stress = st[STATE_HEAD..].iter().fold(0.0f64, |m, s| m.max(s.abs()));
            assert!(stress < 1e-15 * E, "case {case}: point stress {stress:e}");
            assert!(
                internal.abs() < 1e-12 * predicted,
                "case {case}: {internal:e}"
            );
            if projection {
                assert!(
                    hourglass.abs() < 1e-12 * predicted,
                    "case {case}: {hourglass:e}"
                );
            } else {
                assert!(
                    (hourglass - predicted).abs() < 1e-6 * predicted,
                    "case {case}: hourglass {hourglass:e} against {predicted:e}"
                );
                if let Some((e0, w0)) = last {
                    let (e0, w0): (f64, f64) = (e0, w0);
                    let ratio: f64 = hourglass / e0;
                    let expect = (w / w0) * (w / w0);
                    assert!((ratio - expect).abs() < 1e-6 * expect);
                }
                last = Some((hourglass, w));
            }
        }
    }
}

/// A warped plate's rigid spin through 0.01 rad with the plain element: the energy it
/// stores is fixed by the warp and the hourglass stiffness, not by the spin, so its ratio to
/// the kinetic energy falls as the spin rate squared; and it grows as the warp squared.
/// Returns (internal + hourglass) / initial kinetic energy.
fn plain_spin_share(warp: f64, omega: f64) -> (f64, f64) {
    let mut m = random_plate(5, 4, warp);
    m.control.warping_projection = false;
    let n = m.nodes.len() as f64;
    let c = m
        .nodes
        .iter()
        .fold([0.0; 3], |a, p| [0, 1, 2].map(|k| a[k] + p.x[k] / n));
    let mut spin = InitialVelocity::translation(VelocityTarget::All, [0.0; 3]);
    spin.omega = omega;
    spin.centre = c;
    spin.axis = [0.6, 0.8, 0.0];
    m.initial_velocities = vec![spin];
    m.control.end_time = 1.0;
    let mut sim = Simulation::new(&m).unwrap();
    while sim.time() < 0.01 / omega {
        sim.step().unwrap();
    }
    let e = sim.energies();
    ((e.internal + e.hourglass) / e.initial, e.hourglass)
}

#[test]
fn the_plain_elements_spin_energy_scales_with_the_warp_squared_not_the_spin() {
    let (mild, hg_mild) = plain_spin_share(0.01, 500.0);
    let (five, hg_five) = plain_spin_share(0.05, 500.0);
    let (fast, _) = plain_spin_share(0.05, 5000.0);
    eprintln!(
        "share of KE at 500 rad/s: warp 1 % {mild:e}, 5 % {five:e}; 5 % at 5000 rad/s {fast:e}"
    );
    // Warp x5: hourglass energy x25 (the nodes' random heights keep the same pattern).
    let r = hg_five / hg_mild;
    assert!((20.0..30.0).contains(&r), "hourglass energy ratio {r}");
    assert!(mild < 1e-3 && five < 1e-2, "{mild:e} {five:e}");
    // Spin x10: share / 100 (up to the centrifugal stretch of the faster spin).
    assert!(fast < 0.1 * five, "{fast:e} against {five:e}");
}

/// A square quad whose corner node 4 is driven at constant velocity towards node 1, nodes
/// 1 to 3 held, until node 4 has crossed the line through nodes 2 and 3 (a reentrant
/// corner: a negative corner Jacobian, the centre's still positive).
fn dart(distortion_check: bool) -> impactcal_shell::ShellModel {
    use impactcal_shell::{Curve, MotionKind, MotionTarget, PrescribedMotion};
    let l = 0.1;
    let mut m = plate(1, 1, l, l, [0.0; 3]);
    with_section(&mut m, 0.001, aluminium(1));
    m.curves.push(Curve::new(1, vec![(0.0, 1.0), (1.0, 1.0)]));
    let hold = |node, dof, scale| PrescribedMotion {
        target: MotionTarget::Node(node),
        dof,
        kind: MotionKind::Velocity,
        curve: 1,
        scale,
        birth: 0.0,
        death: 1e28,
    };
    for node in 1..=3 {
        for dof in 0..3 {
            m.prescribed.push(hold(node, dof, 0.0));
        }
    }
    m.prescribed.push(hold(4, 0, -20.0));
    m.prescribed.push(hold(4, 1, -20.0));
    m.prescribed.push(hold(4, 2, 0.0));
    m.initial_velocities = vec![InitialVelocity::translation(
        VelocityTarget::Node(4),
        [-20.0, -20.0, 0.0],
    )];
    // Node 4 crosses x + y = l at 2.5 ms and stands at (0.02, 0.02) at 4 ms.
    m.control.end_time = 4e-3;
    m.control.distortion_check = distortion_check;
    m
}

/// The distortion check (`Control::distortion_check`, `*CONTROL_SHELL` NFAIL1 2) stops a
/// run on a quad with a reentrant corner; without it (LS-DYNA's default for one-point
/// shells, a deck without NFAIL1) the quad, evaluated at its centre where the Jacobian is
/// a quarter of its area, carries on: the work of the prescribed motion equals the
/// internal, hourglass and kinetic energy (energy ratio) and the forces stay finite. A
/// written deck keeps the choice; NFAIL1 1 (element deletion) is refused.
#[test]
fn a_reentrant_quad_stops_the_run_only_with_the_distortion_check() {
    let err = Simulation::new(&dart(true)).unwrap().run().unwrap_err();
    assert!(
        matches!(err, ShellError::Unstable { .. }) && err.to_string().contains("inverted"),
        "{err}"
    );
    let r = Simulation::new(&dart(false)).unwrap().run().unwrap();
    let e = r.summary.energies;
    assert!(e.external_work > 0.0 && e.internal > 0.0);
    assert!(
        (r.summary.energy_ratio - 1.0).abs() < 0.01,
        "energy ratio {}",
        r.summary.energy_ratio
    );

    let on = impactcal_shell::keyword::write_deck(&dart(true)).unwrap();
    let read = |d: &str| impactcal_shell::keyword::parse_deck(d, "dart.k").map(|d| d.model);
    assert!(read(&on).unwrap().control.distortion_check);
    let off = impactcal_shell::keyword::write_deck(&dart(false)).unwrap();
    assert!(!read(&off).unwrap().control.distortion_check);
    let nfail1 = format!("{:>10}", 2);
    assert!(on.contains(&format!("\n{nfail1}\n")));
    let deleting = on.replace(&format!("\n{nfail1}\n"), &format!("\n{:>10}\n", 1));
    let msg = read(&deleting).unwrap_err().to_string();
    assert!(msg.contains("NFAIL1"), "{msg}");
}

/// Each of the five hourglass modes of the stiffness form imposed alone on one flat quad,
/// against the closed form of LS-DYNA's Belytschko-Tsay hourglass (Theory Manual, BT
/// section, eqs. 7.15-7.20; Belytschko, Lin and Tsay 1984). The nodal field `h_I d` with
/// `h = (1, -1, 1, -1)` has zero centre strain on any quad (`B_a . h = 0`) and the hourglass
/// rate `q = gamma . h d' = 4 d'` (`gamma . h = h . h = 4`), so after a displacement
/// amplitude `d` the mode holds `Q = C 4 d`, the nodes carry `gamma_I Q` and the stored energy
/// is `C (4 d)^2 / 2 = 8 C d^2`, with, in terms of the diagonals
/// (`B . B = (|d31|^2 + |d42|^2) / (2 A^2)`):
/// membrane `C_m = r_m E t (|d31|^2 + |d42|^2) / (16 A)` (a square: `r E t / 4`, a nodal
/// hourglass stiffness `r E t`); out-of-plane `C_w = r_w k G t^3 (|d31|^2 + |d42|^2) / (24
/// A^2)`; rotation `C_b = r_b E t^3 (|d31|^2 + |d42|^2) / (384 A)`. Different coefficients
/// per mode check that QM, QW and QB reach the modes they name. On a parallelogram
/// `gamma = h` and the nodal forces are checked too; on a general quad the energy.
#[test]
fn each_stiffness_hourglass_mode_of_one_quad_meets_its_closed_form() {
    let (t, a) = (0.002, 0.01);
    let (rm, rw, rb) = (0.03, 0.05, 0.07);
    let hg = Hourglass {
        membrane: rm,
        transverse: rw,
        rotation: rb,
        ..Hourglass::default()
    };
    let mut section = Section::new(1, t);
    section.nip = 5;
    let p = PartProps::new(&section, &aluminium(1), &hg).unwrap();
    let kappa = section.shear_factor;
    let g = E / (2.0 * (1.0 + NU));
    let shapes: [([[f64; 2]; 4], bool); 4] = [
        ([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]], true),
        ([[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]], true),
        ([[0.0, 0.0], [1.5, 0.0], [2.1, 0.8], [0.6, 0.8]], true),
        ([[0.0, 0.0], [1.1, 0.1], [1.0, 0.9], [-0.1, 1.2]], false),
    ];
    const H: [f64; 4] = [1.0, -1.0, 1.0, -1.0];
    let (steps, d) = (1000, 1e-7 * a);
    let dt = 1e-7;
    let rate = d / (steps as f64 * dt);
    for (s, (shape, parallelogram)) in shapes.iter().enumerate() {
        let x0 = shape.map(|q| [q[0] * a, q[1] * a, 0.0]);
        let sub = |i: usize, j: usize| [0, 1, 2].map(|k| x0[i][k] - x0[j][k]);
        let sq = |v: [f64; 3]| v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        let (d31, d42) = (sub(2, 0), sub(3, 1));
        let area = 0.5 * cross(d31, d42)[2];
        let diag = sq(d31) + sq(d42);
        let c = [
            rm * E * t * diag / (16.0 * area),
            rm * E * t * diag / (16.0 * area),
            rw * kappa * g * t.powi(3) * diag / (24.0 * area * area),
            rb * E * t.powi(3) * diag / (384.0 * area),
            rb * E * t.powi(3) * diag / (384.0 * area),
        ];
        // Mode k: component k of the nodal (velocity, angular velocity) pattern h_I.
        for (k, ck) in c.iter().enumerate() {
            let opts = KernelOptions {
                projection: false,
                isdo_diagonal: false,
                invariant: false,
                distortion_check: true,
            };
            let mut st = vec![0.0; STATE_HEAD + 5 * STATE_PER_POINT];
            let (mut hourglass, mut internal) = (0.0, 0.0);
            let mut last = None;
            for n in 1..=steps {
                let u = rate * dt * n as f64;
                let mut x = x0;
                let mut v = [[0.0; 3]; 4];
                let mut w = [[0.0; 3]; 4];
                for i in 0..4 {
                    if k < 3 {
                        x[i][k] += H[i] * u;
                        v[i][k] = H[i] * rate;
                    } else {
                        w[i][k - 3] = H[i] * rate;
                    }
                }
                let out = element::quad(&x, &v, &w, &p, &mut st, dt, opts).unwrap();
                hourglass += out.hourglass;
                internal += out.internal;
                last = Some(out);
            }
            let out = last.unwrap();
            let energy = 8.0 * ck * d * d;
            assert!(
                (hourglass - energy).abs() < 1e-5 * energy,
                "shape {s} mode {k}: hourglass energy {hourglass:e} against {energy:e}"
            );
            assert!(
                internal.abs() < 1e-9 * energy,
                "shape {s} mode {k}: {internal:e}"
            );
            if *parallelogram {
                let q = ck * 4.0 * d;
                for i in 0..4 {
                    for j in 0..6 {
                        let want = if j == k { H[i] * q } else { 0.0 };
                        let got = out.f[i][j];
                        assert!(
                            (got - want).abs() < 1e-5 * q,
                            "shape {s} mode {k}: node {i} component {j}: {got:e} against {want:e}"
                        );
                    }
                }
            }
        }
    }
}
