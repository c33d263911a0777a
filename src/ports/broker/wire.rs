//! What a serving loop needs of a broker link, whichever protocol carries it (MQTT's [`Link`],
//! STOMP's [`StompLink`]): hear, send (messages, and states that the next one makes old),
//! listen to more or fewer topics, flush, count what was dropped, close. The loop above it
//! (`bmlr serve --mqtt | --stomp`) is written once against this.

use std::time::Duration;

use super::{Inbound, Link, StompLink};

/// A broker link seen by a serving loop.
pub trait Wire {
    /// The next thing heard, waiting at most `wait`.
    fn recv_timeout(&self, wait: Duration) -> Option<Inbound>;
    /// What has been heard already, without waiting.
    fn try_recv(&self) -> Option<Inbound>;
    /// Sends `payload` on `topic` (with `headers` where the protocol has them: STOMP).
    fn send(&mut self, topic: &str, payload: Vec<u8>, headers: &[(String, String)]);
    /// Sends a state on `topic` that the next state on it makes old: on MQTT at QoS 0, only the
    /// newest waiting; on STOMP as any message.
    fn send_state(&mut self, topic: &str, payload: Vec<u8>);
    /// Listens to `filter` too (a topic filter; a STOMP destination), now and after every
    /// reconnection.
    fn listen(&mut self, filter: &str);
    /// Stops listening to `filter`.
    fn unlisten(&mut self, filter: &str);
    /// Hands on what waits, as far as the connection takes it.
    fn flush(&mut self);
    /// States heard but dropped so far because the reader fell behind (MQTT; 0 on STOMP,
    /// whose link holds the broker back instead).
    fn states_dropped(&self) -> u64 {
        0
    }
    /// Messages dropped since last asked (the outbox was full while the broker was away).
    fn take_dropped(&mut self) -> u64;
    /// Says it is offline, hands over what waits (for up to `linger`) and disconnects.
    fn close(self: Box<Self>, linger: Duration);
}

impl Wire for Link {
    fn recv_timeout(&self, wait: Duration) -> Option<Inbound> {
        Link::recv_timeout(self, wait)
    }
    fn try_recv(&self) -> Option<Inbound> {
        Link::try_recv(self)
    }
    fn send(&mut self, topic: &str, payload: Vec<u8>, _headers: &[(String, String)]) {
        self.publish(topic, payload, false);
    }
    fn send_state(&mut self, topic: &str, payload: Vec<u8>) {
        self.publish_state(topic, payload);
    }
    fn listen(&mut self, filter: &str) {
        self.subscribe(filter);
    }
    fn unlisten(&mut self, filter: &str) {
        self.unsubscribe(filter);
    }
    fn flush(&mut self) {
        Link::flush(self);
    }
    fn states_dropped(&self) -> u64 {
        Link::states_dropped(self)
    }
    fn take_dropped(&mut self) -> u64 {
        Link::take_dropped(self)
    }
    fn close(self: Box<Self>, linger: Duration) {
        Link::close(*self, linger);
    }
}

impl Wire for StompLink {
    fn recv_timeout(&self, wait: Duration) -> Option<Inbound> {
        StompLink::recv_timeout(self, wait)
    }
    fn try_recv(&self) -> Option<Inbound> {
        StompLink::try_recv(self)
    }
    fn send(&mut self, topic: &str, payload: Vec<u8>, headers: &[(String, String)]) {
        StompLink::send(self, topic, payload, headers);
        StompLink::flush(self);
    }
    fn send_state(&mut self, topic: &str, payload: Vec<u8>) {
        StompLink::send(self, topic, payload, &[]);
    }
    fn listen(&mut self, filter: &str) {
        self.subscribe(filter);
    }
    fn unlisten(&mut self, filter: &str) {
        self.unsubscribe(filter);
    }
    fn flush(&mut self) {
        StompLink::flush(self);
    }
    fn take_dropped(&mut self) -> u64 {
        StompLink::take_dropped(self)
    }
    fn close(self: Box<Self>, linger: Duration) {
        StompLink::close(*self, linger);
    }
}
