//! The realizer on a STOMP 1.2 broker (ActiveMQ Classic and Artemis, RabbitMQ's STOMP plugin):
//! the frames (`frame`) and a link that keeps itself connected (`link`). What travels on it —
//! AsapRealizer's or Greta's topics and messages — is the serving loop's business
//! (`bmlr serve --stomp`, docs/broker.md).

pub mod frame;
mod link;

pub use link::{StompLink, StompOptions, StompUrl, OUTBOX_LIMIT};
