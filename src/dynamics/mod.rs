//! Dynamics for mixed dynamics (van Welbergen et al., JGT 2009; the thesis' chapter 3), in f64:
//! the recursive Newton–Euler inverse dynamics of a kinematic chain of ball joints on a moving
//! connector ([`rnea`]), the angular velocity and acceleration of a joint from its rotations
//! sampled in time ([`kinematics`]), segments' mass properties and spatial inertia ([`mass`]),
//! the zero-phase Butterworth low-pass for stored motion ([`butterworth`]), body
//! configurations — which joints are simulated, which form kinematic chains ([`config`]) — and
//! the simulated body itself: the physical humanoid's parts ([`humanoid`]), one character on
//! rapier3d stepped with its kinematic chains' inverse dynamics ([`sim`]), and the controllers
//! that turn its joints ([`controllers`]), several of them bound together as one ([`compound`]).
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

/// Gravity (m/s², world frame, y up).
pub const GRAVITY: glam::DVec3 = glam::DVec3::new(0.0, -9.81, 0.0);
