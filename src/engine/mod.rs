//! The engine side the scheduler sees. So far: timing models ([`timing`]) — the `Engine` and
//! `PlanUnit` traits and the registry come with the runtime (issue #4).

pub mod timing;
