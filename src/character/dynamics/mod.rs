//! Dynamics for mixed dynamics (van Welbergen et al., JGT 2009; the thesis' chapter 3), in f64:
//! the recursive Newton–Euler inverse dynamics of a kinematic chain of ball joints on a moving
//! connector ([`rnea`]), the angular velocity and acceleration of a joint from its rotations
//! sampled in time ([`kinematics`]), segments' mass properties and spatial inertia ([`mass`]),
//! the zero-phase Butterworth low-pass for stored motion ([`butterworth`]), body
//! configurations — which joints are simulated, which form kinematic chains ([`config`]) — and
//! the simulated body itself: the physical humanoid's parts ([`humanoid`]), one character on
//! rapier3d stepped with its kinematic chains' inverse dynamics ([`sim`]), and the controllers
//! that turn its joints ([`controllers`]), several of them bound together as one ([`compound`]),
//! and the zero-moment point that says how hard the motion is to balance ([`zmp`]).
//! docs/physics.md explains the choices and their measurements.

pub mod butterworth;
pub mod compound;
pub mod config;
pub mod controllers;
pub mod coupling;
pub mod humanoid;
pub mod kinematics;
pub mod mass;
pub mod rnea;
pub mod sim;
pub mod zmp;

use glam::{DQuat, DVec3};
use rapier3d::prelude as rp;

/// A vector as rapier's (f32).
fn v(x: DVec3) -> rp::Vector {
    rp::Vector::new(x.x as f32, x.y as f32, x.z as f32)
}

/// A rapier vector in f64.
fn dv(x: rp::Vector) -> DVec3 {
    DVec3::new(f64::from(x.x), f64::from(x.y), f64::from(x.z))
}

/// A rotation as rapier's (f32, normalized).
fn rot(q: DQuat) -> rp::Rotation {
    rp::Rotation::from_xyzw(q.x as f32, q.y as f32, q.z as f32, q.w as f32).normalize()
}

/// A rapier rotation in f64 (normalized).
fn drot(q: &rp::Rotation) -> DQuat {
    DQuat::from_xyzw(
        f64::from(q.x),
        f64::from(q.y),
        f64::from(q.z),
        f64::from(q.w),
    )
    .normalize()
}

/// Gravity (m/s², world frame, y up).
pub const GRAVITY: glam::DVec3 = glam::DVec3::new(0.0, -9.81, 0.0);
