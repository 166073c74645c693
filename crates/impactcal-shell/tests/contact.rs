//! Segment contact against closed forms and invariants: a point mass on a penalty plate
//! (the stiffness `SLSFAC K A / D`, the contact time and rebound of the mass-spring, the
//! viscous damping VDC), two plates meeting at speed (momentum, energy, no
//! interpenetration), a block sliding on a plate under friction (stopping distance and
//! friction energy), a square tube crushed axially until its folds stack (no node inside a
//! segment beyond a tolerance, energy balance), and bit-identical results for any number of
//! threads.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

mod common;

use common::{plate, rel};
use impactcal_shell::{
    Contact, ContactFriction, ContactKind, ContactSurface, InitialVelocity, Material, MaterialLaw,
    NodeSet, NodeTarget, PartSet, Section, ShellModel, Simulation, Spc, VelocityTarget,
};

fn steel(id: u64, density: f64) -> Material {
    Material {
        id,
        density,
        youngs: 210e9,
        poisson: 0.3,
        law: MaterialLaw::Elastic,
    }
}

/// The distance from `p` to triangle `(a, b, c)`: to its plane when the foot lies inside,
/// otherwise to the nearest edge (written independently of the solver's search).
fn distance_to_triangle(p: [f64; 3], a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    let sub = |u: [f64; 3], v: [f64; 3]| [u[0] - v[0], u[1] - v[1], u[2] - v[2]];
    let dot = |u: [f64; 3], v: [f64; 3]| u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
    let (e0, e1, w) = (sub(b, a), sub(c, a), sub(p, a));
    let (d00, d01, d11) = (dot(e0, e0), dot(e0, e1), dot(e1, e1));
    let (d20, d21) = (dot(w, e0), dot(w, e1));
    let den = d00 * d11 - d01 * d01;
    let v = (d11 * d20 - d01 * d21) / den;
    let u = (d00 * d21 - d01 * d20) / den;
    if v >= 0.0 && u >= 0.0 && u + v <= 1.0 {
        let q = [
            a[0] + v * e0[0] + u * e1[0],
            a[1] + v * e0[1] + u * e1[1],
            a[2] + v * e0[2] + u * e1[2],
        ];
        return dot(sub(p, q), sub(p, q)).sqrt();
    }
    let seg = |s: [f64; 3], t: [f64; 3]| {
        let d = sub(t, s);
        let k = (dot(sub(p, s), d) / dot(d, d)).clamp(0.0, 1.0);
        let q = [s[0] + k * d[0], s[1] + k * d[1], s[2] + k * d[2]];
        dot(sub(p, q), sub(p, q)).sqrt()
    };
    seg(a, b).min(seg(b, c)).min(seg(c, a))
}

/// The largest penetration of any node into any shell that does not hold it: the contact
/// thickness `reach` (half the node's plus half the shell's) less the distance from the
/// node to the shell's mid-surface (a quad as four triangles about its centroid), at the
/// current positions.
fn worst_penetration(m: &ShellModel, sim: &Simulation, reach: f64) -> f64 {
    let index: std::collections::HashMap<u64, usize> = sim
        .node_ids()
        .iter()
        .enumerate()
        .map(|(k, &id)| (id, k))
        .collect();
    let x = sim.positions();
    let mut worst = f64::NEG_INFINITY;
    for s in &m.shells {
        let c: Vec<[f64; 3]> = s.nodes.iter().map(|n| x[index[n]]).collect();
        let centre = [0, 1, 2].map(|d| c.iter().map(|p| p[d]).sum::<f64>() / 4.0);
        for node in &m.nodes {
            if s.nodes.contains(&node.id) {
                continue;
            }
            let p = x[index[&node.id]];
            let d = (0..4)
                .map(|k| distance_to_triangle(p, c[k], c[(k + 1) % 4], centre))
                .fold(f64::INFINITY, f64::min);
            worst = worst.max(reach - d);
        }
    }
    worst
}

/// A rigidly held 3 x 3 plate of 0.1 m squares, 2 mm thick (density `rho`), and a point
/// mass `mass` (node 1000, on no shell) above the middle of the centre square, falling onto
/// it at 1 m/s from 10 um above contact. Returns the model and the contact thickness reach.
fn mass_over_plate(mass: f64, rho: f64, damping: f64) -> (ShellModel, f64) {
    let t = 0.002;
    let mut m = plate(3, 3, 0.3, 0.3, [0.0; 3]);
    m.sections.push(Section::new(1, t));
    m.materials.push(steel(1, rho));
    let ids: Vec<u64> = m.nodes.iter().map(|n| n.id).collect();
    m.node_sets.push(NodeSet { id: 1, nodes: ids });
    m.spcs.push(Spc {
        target: NodeTarget::NodeSet(1),
        dofs: [true; 6],
    });
    let reach = 0.5 * t;
    m.add_node(1000, [0.15, 0.15, reach + 1e-5]);
    m.add_mass(1000, 1000, mass);
    m.node_sets.push(NodeSet {
        id: 2,
        nodes: vec![1000],
    });
    m.initial_velocities.push(InitialVelocity::translation(
        VelocityTarget::Node(1000),
        [0.0, 0.0, -1.0],
    ));
    m.contacts.push(Contact {
        damping,
        ..Contact::between(
            ContactKind::NodesToSurface,
            ContactSurface::NodeSet(2),
            ContactSurface::Part(1),
        )
    });
    m.control.fixed_dt = Some(1e-7);
    m.control.end_time = 2e-4;
    m.output.interval = 1e-7;
    m.output.history_nodes = vec![1000];
    (m, reach)
}

/// The penalty stiffness of a 0.1 m square steel segment: `SLSFAC K A / D` with the bulk
/// modulus `K = E / (3 (1 - 2 nu))`, area `A` and longest diagonal `D`.
fn square_segment_stiffness() -> f64 {
    let bulk = 210e9 / (3.0 * (1.0 - 2.0 * 0.3));
    0.1 * bulk * 0.01 / (0.1 * 2f64.sqrt())
}

/// A point mass on a held plate is a mass on the penalty spring `k = SLSFAC K A / D`: it
/// stays in contact for `pi sqrt(M / k)`, penetrates `v sqrt(M / k)` and leaves at the
/// speed it came with.
#[test]
fn point_mass_on_a_plate_is_a_mass_on_the_penalty_spring() {
    let mass = 1.0;
    let (m, reach) = mass_over_plate(mass, 1e6, 0.0);
    let r = Simulation::new(&m).unwrap().run().unwrap();
    let z: Vec<f64> = r
        .displacement
        .as_ref()
        .unwrap()
        .channel_by_label("1000.z")
        .unwrap()
        .iter()
        .map(|u| u + reach + 1e-5)
        .collect();
    let vz = r
        .velocity
        .as_ref()
        .unwrap()
        .channel_by_label("1000.z")
        .unwrap();
    let dt = 1e-7;
    let k = square_segment_stiffness();
    let below: Vec<usize> = (0..z.len()).filter(|&i| z[i] < reach).collect();
    let cross = |i: usize| {
        // Time at which z crosses `reach` between samples i - 1 and i.
        let s = (z[i - 1] - reach) / (z[i - 1] - z[i]);
        (i as f64 - 1.0 + s) * dt
    };
    let (first, last) = (below[0], *below.last().unwrap());
    let duration = cross(last + 1) - cross(first);
    let depth = reach - z.iter().cloned().fold(f64::INFINITY, f64::min);
    let omega = (k / mass).sqrt();
    eprintln!(
        "contact {duration:.4e} s (pi sqrt(M/k) {:.4e}), depth {depth:.4e} m ({:.4e}), rebound {}",
        std::f64::consts::PI / omega,
        1.0 / omega,
        vz[vz.len() - 1]
    );
    assert!(rel(duration, std::f64::consts::PI / omega) < 2e-3);
    assert!(rel(depth, 1.0 / omega) < 2e-3);
    assert!(rel(vz[vz.len() - 1], 1.0) < 1e-3);
    // The spring's energy went back: the interface holds nothing after the rebound.
    let e = r
        .contacts
        .as_ref()
        .unwrap()
        .channel_by_label("1.energy")
        .unwrap();
    let peak = e.iter().cloned().fold(0.0, f64::max);
    assert!(rel(peak, 0.5 * mass) < 5e-3, "peak contact energy {peak}");
    assert!(e[e.len() - 1].abs() < 1e-3 * peak);
}

/// With VDC the normal dashpot is `c = (VDC / 100) 2 m w`, `w = sqrt(k (m_n + m_s) /
/// (m_n m_s))`, `m = min(m_n, m_s)`; on a heavy plate the mass rebounds as the oscillator
/// `M x'' = max(0, k p - c x')` does.
#[test]
fn contact_damping_follows_the_damped_oscillator() {
    let (mass, vdc) = (1.0, 20.0);
    let (m, _) = mass_over_plate(mass, 1e6, vdc);
    let sim = Simulation::new(&m).unwrap();
    // The centre square's corners are interior nodes of four 0.1 m squares.
    let plate_node = 0.01 * 0.002 * 1e6;
    let k = square_segment_stiffness();
    let omega = (k * (mass + plate_node) / (mass * plate_node)).sqrt();
    let c = vdc / 100.0 * 2.0 * mass * omega;
    // The oscillator, integrated with small steps (RK2 on [x, v], x the penetration).
    let (mut x, mut v, h) = (0.0f64, 1.0f64, 1e-10);
    let force = |x: f64, v: f64| {
        if x > 0.0 {
            (k * x + c * v).max(0.0)
        } else {
            0.0
        }
    };
    loop {
        let a1 = -force(x, v) / mass;
        let (xm, vm) = (x + 0.5 * h * v, v + 0.5 * h * a1);
        let a2 = -force(xm, vm) / mass;
        x += h * vm;
        v += h * a2;
        if x < 0.0 {
            break;
        }
    }
    let r = { sim }.run().unwrap();
    let vz = r
        .velocity
        .as_ref()
        .unwrap()
        .channel_by_label("1000.z")
        .unwrap();
    let out = vz[vz.len() - 1];
    eprintln!("rebound {out} vs oscillator {}", -v);
    assert!(-v < 0.9 && -v > 0.3, "oscillator rebound {}", -v);
    assert!(rel(out, -v) < 5e-3, "rebound {out} vs {}", -v);
}

/// Two 4 x 4 plates (2 mm steel, parts 1 and 2) 1 mm apart flying at each other at 5 m/s
/// each, held together by `contact`; `t` is their thickness.
fn two_plates(contact: Contact) -> (ShellModel, f64) {
    let t = 0.002;
    let mut m = plate(4, 4, 0.1, 0.1, [0.0; 3]);
    let b = plate(4, 4, 0.1, 0.1, [0.008, 0.005, t + 0.001]);
    for n in &b.nodes {
        m.add_node(n.id + 100, n.x);
    }
    for s in &b.shells {
        m.add_shell(s.id + 100, 2, s.nodes.map(|n| n + 100));
    }
    m.add_part(2, 1, 1);
    m.sections.push(Section::new(1, t));
    m.materials.push(steel(1, 7850.0));
    m.part_sets.push(PartSet {
        id: 1,
        parts: vec![1, 2],
    });
    m.initial_velocities.push(InitialVelocity::translation(
        VelocityTarget::Part(1),
        [0.0, 0.0, 5.0],
    ));
    m.initial_velocities.push(InitialVelocity::translation(
        VelocityTarget::Part(2),
        [0.0, 0.0, -5.0],
    ));
    m.contacts.push(contact);
    m.control.end_time = 4e-4;
    (m, t)
}

/// The two plates of [`two_plates`] in a single-surface contact, run to well after they
/// part, with the time-step scale factor `tssfac`: the momentum of the
/// whole, plate A's momentum after, the largest deviation of the energy ratio from 1, the
/// final energy ratio, the interface's energy after, and the worst penetration.
fn plates_meeting(tssfac: f64) -> (f64, f64, f64, f64, f64, f64, f64) {
    let (mut m, t) = two_plates(Contact::single_surface(ContactSurface::PartSet(1)));
    m.control.tssfac = tssfac;
    let mut sim = Simulation::new(&m).unwrap();
    let momentum = |s: &Simulation, part: Option<bool>| {
        let mut p = [0.0; 3];
        for ((v, mass), id) in s.velocities().iter().zip(s.masses()).zip(s.node_ids()) {
            if part.is_some_and(|b| b != (*id > 100)) {
                continue;
            }
            for d in 0..3 {
                p[d] += mass * v[d];
            }
        }
        p
    };
    let p0 = momentum(&sim, Some(false))[2];
    let (mut worst, mut drift, mut off) = (f64::NEG_INFINITY, 0.0f64, 0.0f64);
    while sim.time() < m.control.end_time {
        sim.step().unwrap();
        let p = momentum(&sim, None);
        drift = drift.max(p.iter().map(|c| c.abs()).fold(0.0, f64::max));
        off = off.max((sim.energies().ratio() - 1.0).abs());
        if sim.cycle() % 3 == 0 {
            worst = worst.max(worst_penetration(&m, &sim, t));
        }
    }
    let e = sim.energies();
    let (_, contact, _) = sim.contact_energies()[0];
    (
        drift / p0,
        -momentum(&sim, Some(false))[2] / p0,
        off,
        e.ratio(),
        contact / e.initial,
        worst / t,
        sim.cycle() as f64,
    )
}

/// Two plates meeting at speed in a single-surface contact: linear momentum stays zero to
/// round-off (the forces on a node and on the segment's corners are equal and opposite),
/// each plate leaves with most of its speed reversed (the rest rings on as plate
/// vibration), no node comes inside the other plate beyond a quarter of the contact
/// thickness, and the energy balance closes: within 1 % at the end with the default step,
/// and to second order in the step (the penalty spring of a plate node has `w dt` near 1
/// at TSSFAC 0.9, where kinetic energy at whole steps misreads the spring's exchange while
/// the plates touch; the balance after they part is the measure).
#[test]
fn two_plates_meeting_at_speed_keep_momentum_and_energy() {
    let coarse = plates_meeting(0.9);
    let fine = plates_meeting(0.3);
    for (tss, r) in [(0.9, coarse), (0.3, fine)] {
        let (drift, rebound, off, ratio, contact, worst, cycles) = r;
        eprintln!(
            "TSSFAC {tss}: {cycles} cycles, momentum drift {drift:.2e}, rebound {rebound:.4}, \
             energy ratio off by up to {off:.2e}, final {ratio:.5}, interface energy after {contact:.2e}, \
             worst penetration {worst:.3} t"
        );
        assert!(drift < 1e-12, "momentum drift {drift}");
        assert!(rebound > 0.9 && rebound < 1.0 + 1e-9, "rebound {rebound}");
        assert!(worst < 0.25, "penetration {worst} t");
    }
    assert!(
        (coarse.3 - 1.0).abs() < 0.01,
        "final energy ratio {}",
        coarse.3
    );
    assert!((fine.3 - 1.0).abs() < 1e-3, "final energy ratio {}", fine.3);
    assert!(
        fine.2 < 0.05,
        "energy ratio off by {} while touching",
        fine.2
    );
    assert!(fine.4.abs() < 0.01, "interface energy after {}", fine.4);
    assert!(fine.4.abs() < coarse.4.abs() / 4.0);
}

/// The parts' centre-of-mass velocities (`RunResult::part_velocities`) of the two plates
/// meeting: each starts at its initial velocity, the two (equal masses, no external force)
/// sum to zero at every sample, and after they part each equals the momentum of its nodes
/// over its mass.
#[test]
fn part_velocities_carry_each_plates_momentum() {
    let (m, _) = two_plates(Contact::single_surface(ContactSurface::PartSet(1)));
    let mut sim = Simulation::new(&m).unwrap();
    let r = sim.run().unwrap();
    let v = &r.part_velocities;
    assert_eq!(v.labels(), ["1.vx", "1.vy", "1.vz", "2.vx", "2.vy", "2.vz"]);
    assert!((v.value(2, 0) - 5.0).abs() < 1e-12, "{}", v.value(2, 0));
    assert!((v.value(5, 0) + 5.0).abs() < 1e-12, "{}", v.value(5, 0));
    for k in 0..v.samples() {
        for d in 0..3 {
            let sum = v.value(d, k) + v.value(3 + d, k);
            assert!(sum.abs() < 1e-9, "sample {k}, component {d}: {sum}");
        }
    }
    let (mut p, mut mass) = (0.0, 0.0);
    for ((vel, mn), id) in sim
        .velocities()
        .iter()
        .zip(sim.masses())
        .zip(sim.node_ids())
    {
        if *id < 100 {
            p += mn * vel[2];
            mass += mn;
        }
    }
    let last = v.value(2, v.samples() - 1);
    assert!(last < -4.5, "plate A leaves at {last}");
    assert!(
        (last - p / mass).abs() < 1e-9 * last.abs(),
        "{last} vs {}",
        p / mass
    );
}

/// The interface's sampled forces (`RunResult::contact_forces`) against the momentum the
/// plates exchange. In a surface-to-surface contact the slave side's resultant, integrated
/// over the run, is the momentum plate A (the slave part) gained, component by component;
/// at every sample it is no larger than the summed normal force `fn` (no friction here).
/// In a single-surface contact over both plates every force acts within the one side: the
/// resultant is zero to round-off while `fn` carries the exchange. The sampled interface
/// energy ends at the interface's energy.
#[test]
fn contact_forces_integrate_to_the_momentum_exchanged() {
    let s2s = Contact::between(
        ContactKind::SurfaceToSurface,
        ContactSurface::Part(1),
        ContactSurface::Part(2),
    );
    for (contact, single) in [
        (s2s, false),
        (Contact::single_surface(ContactSurface::PartSet(1)), true),
    ] {
        let (m, _) = two_plates(contact);
        let mut sim = Simulation::new(&m).unwrap();
        let plate_a = |s: &Simulation| {
            let mut p = [0.0; 3];
            for ((v, mass), id) in s.velocities().iter().zip(s.masses()).zip(s.node_ids()) {
                if *id < 100 {
                    for d in 0..3 {
                        p[d] += mass * v[d];
                    }
                }
            }
            p
        };
        let p0 = plate_a(&sim);
        let r = sim.run().unwrap();
        let p1 = plate_a(&sim);
        let f = r.contact_forces.as_ref().unwrap();
        assert_eq!(f.labels(), ["1.fx", "1.fy", "1.fz", "1.fn"]);
        let dt = f.dt();
        let integral: Vec<f64> = (0..4)
            .map(|c| f.channel(c).iter().sum::<f64>() * dt)
            .collect();
        let exchanged = (p1[2] - p0[2]).abs();
        assert!(exchanged > 0.9 * 2.0 * p0[2].abs(), "{exchanged} vs {p0:?}");
        for k in 0..f.samples() {
            let g = [f.value(0, k), f.value(1, k), f.value(2, k)];
            let size = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
            assert!(
                size <= f.value(3, k) * (1.0 + 1e-9) + 1e-9,
                "sample {k}: {g:?}"
            );
        }
        assert!(integral[3] >= exchanged * (1.0 - 1e-9), "{integral:?}");
        eprintln!(
            "single surface {single}: integral {integral:?}, plate A gained {:?}",
            [p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]]
        );
        for d in 0..3 {
            if single {
                assert!(integral[d].abs() < 1e-9 * exchanged, "{integral:?}");
            } else {
                assert!(
                    (integral[d] - (p1[d] - p0[d])).abs() < 1e-9 * exchanged,
                    "component {d}: {integral:?} vs {:?}",
                    [p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]]
                );
            }
        }
        let e = r.contacts.as_ref().unwrap();
        assert_eq!(e.labels(), ["1.energy", "1.friction"]);
        let (_, energy, friction) = sim.contact_energies()[0];
        assert_eq!(e.value(0, e.samples() - 1), energy);
        assert_eq!(e.value(1, e.samples() - 1), friction);
    }
}

/// A block (one 0.1 m square with 2.5 kg at each corner) launched at 2 m/s along a held
/// plate under gravity with Coulomb friction 0.3 stops after `v^2 / (2 mu g)`, and the
/// friction energy is the kinetic energy it had.
#[test]
fn block_sliding_on_a_plate_stops_at_the_coulomb_distance() {
    let (t, mu, g, v0) = (0.002, 0.3, 9.81, 2.0);
    let mut m = plate(12, 2, 1.2, 0.2, [0.0; 3]);
    let ids: Vec<u64> = m.nodes.iter().map(|n| n.id).collect();
    m.node_sets.push(NodeSet { id: 1, nodes: ids });
    m.spcs.push(Spc {
        target: NodeTarget::NodeSet(1),
        dofs: [true; 6],
    });
    let z = t;
    for (k, (x, y)) in [(0.05, 0.05), (0.15, 0.05), (0.15, 0.15), (0.05, 0.15)]
        .iter()
        .enumerate()
    {
        m.add_node(500 + k as u64, [*x, *y, z]);
        m.add_mass(500 + k as u64, 500 + k as u64, 2.5);
    }
    m.add_shell(500, 2, [500, 501, 502, 503]);
    m.add_part(2, 1, 1);
    m.sections.push(Section::new(1, t));
    m.materials.push(steel(1, 7850.0));
    m.initial_velocities.push(InitialVelocity::translation(
        VelocityTarget::Part(2),
        [v0, 0.0, 0.0],
    ));
    m.set_gravity(g);
    m.contacts.push(Contact {
        friction: ContactFriction {
            static_coef: mu,
            dynamic: mu,
            ..ContactFriction::default()
        },
        damping: 40.0,
        ..Contact::between(
            ContactKind::NodesToSurface,
            ContactSurface::Part(2),
            ContactSurface::Part(1),
        )
    });
    let stop = v0 * v0 / (2.0 * mu * g);
    m.control.end_time = 1.2 * v0 / (mu * g);
    m.output.interval = 1e-3;
    m.output.history_nodes = vec![500];
    let mut sim = Simulation::new(&m).unwrap();
    let block_mass: f64 = sim
        .masses()
        .iter()
        .zip(sim.node_ids())
        .filter(|(_, id)| **id >= 500)
        .map(|(m, _)| m)
        .sum();
    let r = sim.run().unwrap();
    let ux = r
        .displacement
        .as_ref()
        .unwrap()
        .channel_by_label("500.x")
        .unwrap();
    let uz = r
        .displacement
        .as_ref()
        .unwrap()
        .channel_by_label("500.z")
        .unwrap();
    let travel = ux[ux.len() - 1];
    let friction = r
        .contacts
        .as_ref()
        .unwrap()
        .channel_by_label("1.friction")
        .unwrap();
    let e_f = friction[friction.len() - 1];
    let ke = 0.5 * block_mass * v0 * v0;
    eprintln!(
        "travel {travel:.4} m (v^2/(2 mu g) {stop:.4}), friction energy {e_f:.3} J of {ke:.3} J, sinking {:.2e} m, energy ratio {}",
        -uz.iter().cloned().fold(0.0, f64::min),
        r.summary.energy_ratio
    );
    assert!(rel(travel, stop) < 0.02, "travel {travel} vs {stop}");
    assert!(rel(e_f, ke) < 0.02, "friction energy {e_f} vs {ke}");
    assert!(uz.iter().all(|u| u.abs() < 0.1 * t));
}

/// A full square steel tube 50 x 50 x 3 mm, 100 mm long (32 quads of 6.25 mm round, 16
/// along), elastic-perfectly plastic at 250 MPa, on the rigid floor under a 100 kg striker
/// at 10 m/s (both end rings held square), seeded by a small dent pattern in the symmetric
/// folding mode; with a single-surface contact over the tube when `contact`. Returns the
/// model and the contact thickness (the thickness, or 0.4 of the element's edge if less).
fn square_tube(contact: bool) -> (ShellModel, f64) {
    let (b, t, l, m_half, nz) = (0.05f64, 0.003f64, 0.1, 4u64, 16u64);
    let mut m = ShellModel::new("square tube crush");
    let per_face = 2 * m_half;
    let ring = 4 * per_face;
    let h = b / per_face as f64;
    let fold = 0.99 * t.powf(1.0 / 3.0) * b.powf(2.0 / 3.0);
    for k in 0..=nz {
        let z = l * k as f64 / nz as f64;
        for i in 0..ring {
            let (face, u) = (i / per_face, (i % per_face) as f64 * h - 0.5 * b);
            let (x, y, nx, ny) = match face {
                0 => (u, -0.5 * b, 0.0, -1.0),
                1 => (0.5 * b, u, 1.0, 0.0),
                2 => (-u, 0.5 * b, 0.0, 1.0),
                _ => (-0.5 * b, -u, -1.0, 0.0),
            };
            let sign = if face % 2 == 0 { 1.0 } else { -1.0 };
            let d = 0.05
                * t
                * sign
                * (std::f64::consts::PI * (u + 0.5 * b) / b).sin()
                * (std::f64::consts::PI * z / fold).sin();
            m.add_node(1 + i + k * ring, [x + d * nx, y + d * ny, z]);
        }
    }
    for k in 0..nz {
        for i in 0..ring {
            let (n1, n2) = (1 + i + k * ring, 1 + (i + 1) % ring + k * ring);
            m.add_shell(1 + i + k * ring, 1, [n1, n2, n2 + ring, n1 + ring]);
        }
    }
    m.add_part(1, 1, 1);
    m.sections.push(Section::new(1, t));
    m.materials.push(Material {
        id: 1,
        density: 7850.0,
        youngs: 210e9,
        poisson: 0.3,
        law: MaterialLaw::Plastic {
            yield_stress: 250e6,
            tangent_modulus: 0.0,
            rate: None,
        },
    });
    let top: Vec<u64> = (0..ring).map(|i| 1 + i + nz * ring).collect();
    let bottom: Vec<u64> = (0..ring).map(|i| 1 + i).collect();
    for (j, &id) in top.iter().enumerate() {
        m.add_mass(10_000 + j as u64, id, 100.0 / ring as f64);
    }
    m.node_sets.push(NodeSet { id: 1, nodes: top });
    m.node_sets.push(NodeSet {
        id: 2,
        nodes: bottom,
    });
    m.initial_velocities.push(InitialVelocity::translation(
        VelocityTarget::NodeSet(1),
        [0.0, 0.0, -10.0],
    ));
    for set in [1, 2] {
        m.spcs.push(Spc {
            target: NodeTarget::NodeSet(set),
            dofs: [true, true, false, true, true, true],
        });
    }
    m.walls
        .push(impactcal_shell::RigidWall::plane([0.0; 3], [0.0, 0.0, 1.0]));
    if contact {
        m.contacts
            .push(Contact::single_surface(ContactSurface::Part(1)));
    }
    (m, t.min(0.4 * h))
}

/// The square tube crushed by 55 mm, until its folds lie on each other: with the
/// single-surface contact no node comes inside a segment by more than 20 % of the contact
/// thickness (checked every 100 cycles against every shell), and the energy balance
/// closes to 2 %; without contact nodes pass through the folds (beyond half the contact
/// thickness, where the check stops).
#[test]
fn square_tube_folds_without_interpenetration() {
    let crush = 0.055;
    let mut outcome = Vec::new();
    for contact in [true, false] {
        let (mut m, reach) = square_tube(contact);
        m.control.end_time = crush / 9.0;
        let mut sim = Simulation::new(&m).unwrap();
        let (mut worst, mut off) = (f64::NEG_INFINITY, 0.0f64);
        while sim.time() < m.control.end_time && worst < 0.5 * reach {
            sim.step().unwrap();
            off = off.max((sim.energies().ratio() - 1.0).abs());
            if sim.cycle() % 100 == 0 {
                worst = worst.max(worst_penetration(&m, &sim, reach));
            }
        }
        let e = sim.energies();
        let (_, interface, _) = sim.contact_energies().first().copied().unwrap_or_default();
        eprintln!(
            "contact {contact}: t {:.3e} of {:.3e}, {} cycles, worst penetration {:.3} of the contact thickness, energy ratio off by up to {off:.3e}, internal {:.1} J, hourglass {:.1} J, interface {interface:.2} J",
            sim.time(),
            m.control.end_time,
            sim.cycle(),
            worst / reach,
            e.internal,
            e.hourglass
        );
        outcome.push((sim.time() >= m.control.end_time, worst / reach, off));
    }
    let (done, worst, off) = outcome[0];
    assert!(done, "the crush with contact did not finish");
    assert!(worst < 0.2, "penetration {worst} of the contact thickness");
    assert!(off < 0.02, "energy ratio off by {off}");
    assert!(
        outcome[1].1 >= 0.5,
        "without contact the folds should pass through each other"
    );
}

/// Contact with friction and damping gives bit-identical results on 1, 2 and 3 threads
/// (fixed chunks of nodes, forces added in node order).
#[test]
fn contact_is_bit_identical_for_any_number_of_threads() {
    let (mut m, _) = square_tube(true);
    m.contacts[0].friction = ContactFriction {
        static_coef: 0.3,
        dynamic: 0.2,
        decay: 0.5,
        viscous: 0.0,
    };
    m.contacts[0].damping = 10.0;
    m.control.end_time = 0.04 / 9.0;
    m.output.history_nodes = vec![1, 100, 300];
    m.output.interval = 5e-5;
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| Simulation::new(&m).unwrap().run().unwrap())
    };
    let a = run(1);
    let friction = a
        .contacts
        .as_ref()
        .unwrap()
        .channel_by_label("1.friction")
        .unwrap();
    assert!(friction[friction.len() - 1] > 0.0);
    for threads in [2, 3] {
        let b = run(threads);
        assert_eq!(a.velocity, b.velocity);
        assert_eq!(a.energies, b.energies);
        assert_eq!(a.contacts, b.contacts);
    }
}
