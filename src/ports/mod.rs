//! The ports floor, the top: the realizer as other programs meet it, above the realizer
//! itself — on MQTT and STOMP brokers with ipaaca's, AsapRealizer's and Greta's conventions
//! ([`broker`], feature `broker`), as a port of the RealizerTester conformance suite
//! ([`conformance`], feature `conformance`), and as pictures of plans and logs ([`timeline`]).

#[cfg(feature = "broker")]
pub mod broker;
#[cfg(feature = "conformance")]
pub mod conformance;
pub mod timeline;
