//! The realizer on an MQTT broker: the topic layout (`topics`), the broker's address
//! (`BrokerUrl`) and a link to the broker that keeps itself connected (`link`). The serving loop
//! (`bmlr serve --mqtt`) sits above them in the command line; this module knows nothing of
//! the realizer's plan. It follows the contract of `docs/broker.md`: BML in per character,
//! feedback out per character, presence retained with a last will, QoS 1 throughout.

mod link;
mod topics;

pub use link::{Inbound, Link, LinkOptions, OUTBOX_LIMIT};
pub use topics::{level_ok, BrokerUrl, Topics, DEFAULT_CHARACTER};
