//! The realizer on a message broker: MQTT's topic layout (`topics`), the broker's address
//! (`BrokerUrl`), a link to the broker that keeps itself connected (`link`), ipaaca as ipaacar
//! speaks it over MQTT (`ipaaca`), a STOMP 1.2 link for ActiveMQ and its kin (`stomp`), what a
//! serving loop needs of either link (`wire`), and the characters' root states that realizers
//! sharing one world exchange (`state`) on the topics of the floor's cells (`cells`). The serving loop (`bmlr serve --mqtt | --stomp`) sits
//! above them in the command line; this module knows nothing of the realizer's plan. It follows
//! the contract of `docs/broker.md`.

mod cells;
pub mod ipaaca;
mod link;
mod state;
pub mod stomp;
mod topics;
mod wire;

pub use cells::{Cell, Cells, CELL_SIZE, CELL_SIZES, KEEP_MARGIN, LISTEN_RADIUS};
pub use ipaaca::Ipaaca;
pub use link::{Inbound, Link, LinkOptions, OUTBOX_LIMIT};
pub use state::{RootState, EXTRAPOLATE, PUBLISH_PERIOD, REST_PERIOD, STALE};
pub use stomp::{StompLink, StompOptions, StompUrl};
pub use topics::{level_ok, BrokerUrl, Topics, DEFAULT_CHARACTER};
pub use wire::Wire;
