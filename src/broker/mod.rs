//! The realizer on an MQTT broker: the topic layout (`topics`), the broker's address
//! (`BrokerUrl`), a link to the broker that keeps itself connected (`link`) and the characters'
//! root states that realizers sharing one world exchange (`state`). The serving loop
//! (`bmlr serve --mqtt`) sits above them in the command line; this module knows nothing of
//! the realizer's plan. It follows the contract of `docs/broker.md`: BML in per character,
//! feedback out per character, presence retained with a last will, QoS 1 throughout.

mod ipaaca;
mod link;
mod state;
mod topics;

pub use ipaaca::Ipaaca;
pub use link::{Inbound, Link, LinkOptions, OUTBOX_LIMIT};
pub use state::{RootState, EXTRAPOLATE, PUBLISH_PERIOD};
pub use topics::{level_ok, BrokerUrl, Topics, DEFAULT_CHARACTER};
