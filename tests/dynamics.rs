//! Inverse dynamics against independent answers: a random three-link chain of ball joints,
//! whose joint torques must equal the Newton–Euler equations of each joint's whole subtree written
//! in the world frame with the kinematics taken by numerically differentiating forward kinematics
//! (no recursion, no link frames); the joint-space equations τ = H(q) q̈ + C(q, q̇) + G(q) built
//! from the links' Jacobians; and gravity as an upward base acceleration against gravity as forces
//! at the centres of mass.

use bml_realizer::character::dynamics::rnea::{
    inverse_dynamics, with_gravity, BaseMotion, JointMotion, Link,
};
use bml_realizer::character::dynamics::GRAVITY;
use glam::{DMat3, DQuat, DVec3};

/// A small deterministic generator (splitmix64).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.next()
    }
    fn vec(&mut self, a: f64) -> DVec3 {
        DVec3::new(self.range(-a, a), self.range(-a, a), self.range(-a, a))
    }
    fn unit(&mut self) -> DVec3 {
        self.vec(1.0).normalize()
    }
}

/// A joint turning about axis `a` by θa(t) and then about `b` by θb(t), θ = A sin(Ωt + φ).
#[derive(Clone, Copy)]
struct Swing {
    a: DVec3,
    b: DVec3,
    wave: [(f64, f64, f64); 2],
}

impl Swing {
    fn angle(&self, k: usize, t: f64) -> (f64, f64, f64) {
        let (amp, om, ph) = self.wave[k];
        let s = om * t + ph;
        (amp * s.sin(), amp * om * s.cos(), -amp * om * om * s.sin())
    }

    fn rotation(&self, t: f64) -> DQuat {
        DQuat::from_axis_angle(self.a, self.angle(0, t).0)
            * DQuat::from_axis_angle(self.b, self.angle(1, t).0)
    }

    /// The joint's motion with its velocity and acceleration worked out by hand (child frame).
    fn motion(&self, t: f64) -> JointMotion {
        let ((_, da, dda), (b, db, ddb)) = (self.angle(0, t), self.angle(1, t));
        let qb_inv = DQuat::from_axis_angle(self.b, b).inverse();
        let wa = qb_inv * (self.a * da);
        JointMotion {
            rotation: self.rotation(t),
            velocity: wa + self.b * db,
            acceleration: qb_inv * (self.a * dda) - (self.b * db).cross(wa) + self.b * ddb,
        }
    }
}

fn chain(rng: &mut Rng) -> (Vec<Link>, Vec<Swing>) {
    let mut links = Vec::new();
    let mut swings = Vec::new();
    for i in 0..3usize {
        let spin = DMat3::from_quat(DQuat::from_axis_angle(rng.unit(), rng.range(0.0, 3.0)));
        let diag = DMat3::from_diagonal(DVec3::new(
            rng.range(0.01, 0.2),
            rng.range(0.01, 0.2),
            rng.range(0.01, 0.2),
        ));
        links.push(Link {
            parent: i.checked_sub(1),
            offset: if i == 0 { DVec3::ZERO } else { rng.vec(0.4) },
            mass: rng.range(0.5, 5.0),
            com: rng.vec(0.3),
            inertia: spin * diag * spin.transpose(),
        });
        let mut wave = || {
            (
                rng.range(0.2, 1.2),
                rng.range(0.5, 4.0),
                rng.range(0.0, 6.0),
            )
        };
        let w = [wave(), wave()];
        swings.push(Swing {
            a: rng.unit(),
            b: rng.unit(),
            wave: w,
        });
    }
    (links, swings)
}

/// World poses of the links at time t: (joint position, orientation).
fn world(links: &[Link], swings: &[Swing], t: f64) -> Vec<(DVec3, DQuat)> {
    let mut out: Vec<(DVec3, DQuat)> = Vec::new();
    for (i, l) in links.iter().enumerate() {
        let (pp, pq) = l.parent.map_or((DVec3::ZERO, DQuat::IDENTITY), |p| out[p]);
        out.push((pp + pq * l.offset, pq * swings[i].rotation(t)));
    }
    out
}

/// The derivative of f at t by the fourth-order central difference.
fn d1<F: Fn(f64) -> DVec3>(f: F, t: f64, h: f64) -> DVec3 {
    (f(t - 2.0 * h) - 8.0 * f(t - h) + 8.0 * f(t + h) - f(t + 2.0 * h)) / (12.0 * h)
}

/// The second derivative by the fourth-order central difference.
fn d2<F: Fn(f64) -> DVec3>(f: F, t: f64, h: f64) -> DVec3 {
    (-f(t - 2.0 * h) + 16.0 * f(t - h) - 30.0 * f(t) + 16.0 * f(t + h) - f(t + 2.0 * h))
        / (12.0 * h * h)
}

/// World angular velocity of link i: 2 q̇ q⁻¹, q̇ by central differences of the quaternion.
fn world_rate(links: &[Link], swings: &[Swing], i: usize, t: f64, h: f64) -> DVec3 {
    let q = |t: f64| world(links, swings, t)[i].1;
    let v = |t: f64| {
        let x = q(t);
        let x = if x.dot(q(0.0)) < 0.0 { -x } else { x };
        DVec3::new(x.x, x.y, x.z) // the vector part; w follows from it
    };
    let w4 = |t: f64| q(t).w;
    let dq = d1(v, t, h);
    let dw = (w4(t - 2.0 * h) - 8.0 * w4(t - h) + 8.0 * w4(t + h) - w4(t + 2.0 * h)) / (12.0 * h);
    let qt = q(t);
    let dq = DQuat::from_xyzw(dq.x, dq.y, dq.z, dw);
    let w = (dq * qt.inverse()) * 2.0;
    DVec3::new(w.x, w.y, w.z)
}

/// Whether link `i` is `j` or hangs below it.
fn in_subtree(links: &[Link], i: usize, j: usize) -> bool {
    let mut k = Some(i);
    while let Some(x) = k {
        if x == j {
            return true;
        }
        k = links[x].parent;
    }
    false
}

/// Joint torques (world frame) from each subtree's Newton–Euler equations.
fn subtree_torques(links: &[Link], swings: &[Swing], t: f64) -> Vec<DVec3> {
    let h = 1e-3;
    let poses = world(links, swings, t);
    let com = |i: usize| {
        move |t: f64| {
            let p = world(links, swings, t)[i];
            p.0 + p.1 * links[i].com
        }
    };
    (0..links.len())
        .map(|j| {
            let pj = poses[j].0;
            (0..links.len())
                .filter(|&i| in_subtree(links, i, j))
                .map(|i| {
                    let r = DMat3::from_quat(poses[i].1);
                    let inertia = r * links[i].inertia * r.transpose();
                    let w = world_rate(links, swings, i, t, h);
                    let dw = d1(|t| world_rate(links, swings, i, t, h), t, h);
                    let a = d2(com(i), t, h);
                    (com(i)(t) - pj).cross(links[i].mass * (a - GRAVITY))
                        + inertia * dw
                        + w.cross(inertia * w)
                })
                .sum()
        })
        .collect()
}

/// Compares the inverse dynamics (gravity as an upward base acceleration) with `want`, each
/// joint's torque in its link's frame, on five random chains from `seed` at eight instants
/// each (`t0`, `t0 + dt`, …): every relative difference below 1e-9. Returns the worst.
fn worst_difference(
    seed: u64,
    (t0, dt): (f64, f64),
    mut want: impl FnMut(&[Link], &[Swing], f64, &[JointMotion]) -> Vec<DVec3>,
) -> f64 {
    let mut rng = Rng(seed);
    let mut worst = 0.0f64;
    for _ in 0..5 {
        let (links, swings) = chain(&mut rng);
        for k in 0..8 {
            let t = t0 + k as f64 * dt;
            let joints: Vec<JointMotion> = swings.iter().map(|s| s.motion(t)).collect();
            let got = inverse_dynamics(
                &links,
                &joints,
                with_gravity(BaseMotion::default(), DQuat::IDENTITY),
            )
            .torques;
            let want = want(&links, &swings, t, &joints);
            for j in 0..3 {
                let err = (got[j] - want[j]).length() / want[j].length().max(1.0);
                worst = worst.max(err);
                assert!(
                    err < 1e-9,
                    "joint {j} at {t}: {} vs {}: {err:e}",
                    got[j],
                    want[j]
                );
            }
        }
    }
    worst
}

#[test]
fn rnea_equals_the_subtree_newton_euler_equations_on_a_random_chain() {
    let worst = worst_difference(42, (0.1, 0.23), |links, swings, t, _| {
        // the subtree equations are in the world frame
        let poses = world(links, swings, t);
        let world_torques = subtree_torques(links, swings, t);
        (0..3)
            .map(|j| poses[j].1.inverse() * world_torques[j])
            .collect()
    });
    // the numerical differences of the kinematics limit the agreement: 4.4e-10 at worst here
    eprintln!("worst relative difference {worst:e}");
}

#[test]
fn gravity_as_an_upward_base_acceleration_equals_weights_at_the_centres_of_mass() {
    let mut rng = Rng(7);
    let (links, swings) = chain(&mut rng);
    let t = 0.77;
    let joints: Vec<JointMotion> = swings.iter().map(|s| s.motion(t)).collect();
    let with = inverse_dynamics(
        &links,
        &joints,
        with_gravity(BaseMotion::default(), DQuat::IDENTITY),
    );
    let without = inverse_dynamics(&links, &joints, BaseMotion::default());
    let poses = world(&links, &swings, t);
    for j in 0..3 {
        // the moment about joint j of the weights of its subtree, held up by the joint
        let weights: DVec3 = (j..3)
            .map(|i| {
                (poses[i].0 + poses[i].1 * links[i].com - poses[j].0)
                    .cross(-links[i].mass * GRAVITY)
            })
            .sum();
        let got = poses[j].1 * (with.torques[j] - without.torques[j]);
        assert!(
            (got - weights).length() <= 1e-10 * weights.length().max(1.0),
            "{got} vs {weights}"
        );
    }
}

/// The skew matrix of `r`: `skew(r) * u == r × u`.
fn skew(r: DVec3) -> DMat3 {
    DMat3::from_cols(
        DVec3::new(0.0, r.z, -r.y),
        DVec3::new(-r.z, 0.0, r.x),
        DVec3::new(r.y, -r.x, 0.0),
    )
}

/// The chain in joint space at one instant, worked out from the link Jacobians with no recursion
/// and no numerical differences. The coordinates are the joints' relative angular velocities in
/// their child links' frames (three per ball joint), the same as the inverse dynamics' inputs.
struct JointSpace {
    /// Mass matrix H(q), a 3 × 3 grid of 3 × 3 blocks: `h[k][l]` couples joints k and l.
    h: Vec<Vec<DMat3>>,
    /// Velocity products C(q, q̇) plus gravity G(q), per joint.
    bias: Vec<DVec3>,
}

impl JointSpace {
    fn new(links: &[Link], poses: &[(DVec3, DQuat)], joints: &[JointMotion]) -> JointSpace {
        let n = links.len();
        let rot: Vec<DMat3> = poses.iter().map(|p| DMat3::from_quat(p.1)).collect();
        let com: Vec<DVec3> = (0..n).map(|i| poses[i].0 + rot[i] * links[i].com).collect();
        // world axes of the joints' velocities, and each link's angular velocity
        let turn: Vec<DVec3> = (0..n).map(|k| rot[k] * joints[k].velocity).collect();
        let ups = |i: usize| (0..n).filter(move |&k| in_subtree(links, i, k));
        let omega: Vec<DVec3> = (0..n).map(|i| ups(i).map(|k| turn[k]).sum()).collect();
        // velocity of a point p moving with link i
        let speed =
            |i: usize, p: DVec3| -> DVec3 { ups(i).map(|k| turn[k].cross(p - poses[k].0)).sum() };
        let joint_speed = |k: usize| {
            links[k]
                .parent
                .map_or(DVec3::ZERO, |p| speed(p, poses[k].0))
        };
        let (mut h, mut bias) = (vec![vec![DMat3::ZERO; n]; n], vec![DVec3::ZERO; n]);
        for i in 0..n {
            let inertia = rot[i] * links[i].inertia * rot[i].transpose();
            let m = links[i].mass;
            // the Jacobian blocks of link i: angular R_k, linear −[c_i − o_k]× R_k
            let jw = |k: usize| rot[k];
            let jv = |k: usize| skew(poses[k].0 - com[i]) * rot[k];
            // J̇ q̇: the accelerations with every joint's acceleration zero
            let dot_w: DVec3 = ups(i).map(|k| omega[k].cross(turn[k])).sum();
            let dot_v: DVec3 = ups(i)
                .map(|k| {
                    let r = com[i] - poses[k].0;
                    let dr = speed(i, com[i]) - joint_speed(k);
                    omega[k].cross(turn[k]).cross(r) + turn[k].cross(dr)
                })
                .sum();
            let force = m * (dot_v - GRAVITY);
            let moment = inertia * dot_w + omega[i].cross(inertia * omega[i]);
            for k in ups(i) {
                bias[k] += jv(k).transpose() * force + jw(k).transpose() * moment;
                for l in ups(i) {
                    h[k][l] += m * jv(k).transpose() * jv(l) + jw(k).transpose() * inertia * jw(l);
                }
            }
        }
        JointSpace { h, bias }
    }

    /// τ = H(q) q̈ + C(q, q̇) + G(q), per joint.
    fn torques(&self, joints: &[JointMotion]) -> Vec<DVec3> {
        (0..joints.len())
            .map(|k| {
                let hq: DVec3 = (0..joints.len())
                    .map(|l| self.h[k][l] * joints[l].acceleration)
                    .sum();
                hq + self.bias[k]
            })
            .collect()
    }

    /// xᵀ H x for a joint-space vector x.
    fn energy(&self, x: &[DVec3]) -> f64 {
        (0..x.len())
            .flat_map(|k| (0..x.len()).map(move |l| (k, l)))
            .map(|(k, l)| x[k].dot(self.h[k][l] * x[l]))
            .sum()
    }
}

/// The inverse dynamics equals an independent τ = H(q) q̈ + C(q, q̇) + G(q), the joint-space
/// equations built from the links' Jacobians, on random chains with analytic q̇ and q̈ (thesis
/// §3.3). Both are exact, so they agree to rounding.
#[test]
fn rnea_equals_h_q_ddot_plus_c_on_a_random_chain() {
    let mut motions = Rng(7);
    let worst = worst_difference(2009, (0.05, 0.31), |links, swings, t, joints| {
        let poses = world(links, swings, t);
        let space = JointSpace::new(links, &poses, joints);
        // H is a mass matrix: symmetric, and the kinetic energy of any motion positive
        for a in 0..3 {
            for b in 0..3 {
                let asym =
                    (space.h[a][b] - space.h[b][a].transpose()).abs_diff_eq(DMat3::ZERO, 1e-12);
                assert!(asym, "H not symmetric in blocks {a}, {b}");
            }
        }
        let x: Vec<DVec3> = (0..3).map(|_| motions.vec(1.0)).collect();
        assert!(space.energy(&x) > 0.0, "H not positive definite at {t}");
        space.torques(joints)
    });
    eprintln!("worst relative difference {worst:e}");
}
