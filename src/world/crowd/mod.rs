//! Crowds: walkers that share space. After the social path following of Karamouzas and
//! Overmars as extended in the "Social Path Following" thesis (Ch. 5): each walker, several
//! times a second, lists the people it would touch within a few seconds if everyone kept their
//! course (time to contact, with radii widened to a personal space), widens the speeds and
//! headings it considers the sooner the first contact comes, samples them in a fixed order
//! (the desired velocity, then to the right, then to the left, each sample jittered) and takes
//! the cheapest by a cost of effort, deviation and collision risk; once it has chosen a side it
//! keeps it; it walks round the space of conversing groups ([`group`]) and asks those standing in its way to make room ([`negotiate`]); at a door too narrow to pass
//! each other in, walkers coming from both sides take turns ([`doorway`]). [`profile`] holds the per-character parameters, [`contact`] the time to contact,
//! [`snapshot`] the crowd as every walker sees it in a frame (with a uniform grid to find
//! neighbours), [`avoid`] the choice itself. The realizer keeps the crowd on a fixed grid of
//! times (every 0.1 s of global time, whatever the host's frames) and each walker
//! (`locomotion::walker`) chooses among the others between its route and its gait
//! (`docs/crowds.md`).

pub mod avoid;
pub mod contact;
pub mod doorway;
pub mod group;
pub mod lanes;
pub mod negotiate;
pub mod profile;
pub mod quality;
pub mod scenes;
pub mod sim;
pub mod snapshot;

pub use avoid::Avoider;
pub use profile::Profile;
pub use snapshot::{Agent, Crowd};
