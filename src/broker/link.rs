//! A link to an MQTT broker that keeps itself connected: rumqttc's blocking client, its
//! connection polled on a thread of its own. Every (re)connection renews the subscriptions and
//! the presence (retained `online`, with `offline` as the last will), since a broker that
//! restarted has forgotten both. What arrives waits in a bounded inbox (the polling thread
//! waits when it is full, and the broker holds back: backpressure); what is sent goes at QoS 1
//! through rumqttc's bounded request queue, and, while that is full (a broker away), into an
//! outbox of at most [`OUTBOX_LIMIT`] messages, beyond which the oldest are dropped and counted
//! ([`Link::take_dropped`]). TCP_NODELAY is set: without it small messages wait for the
//! previous one's acknowledgement (Nagle's algorithm, ~40 ms stalls).

use std::collections::VecDeque;
use std::sync::mpsc::{self, Receiver, SyncSender};
use std::time::{Duration, Instant};

use rumqttc::{Client, ClientError, Event, LastWill, MqttOptions, Packet, QoS, Request};

use super::BrokerUrl;

/// Messages kept while the broker is away, beyond rumqttc's own queue.
pub const OUTBOX_LIMIT: usize = 100_000;

/// rumqttc's request queue (messages handed to its event loop, not yet written).
const REQUESTS: usize = 4_096;

/// The largest packet taken from the broker (bytes); a larger one ends the connection (which
/// is then made again).
pub const MAX_PACKET: usize = 16 << 20;

/// How a link connects.
#[derive(Debug, Clone)]
pub struct LinkOptions {
    /// The broker.
    pub url: BrokerUrl,
    /// The client id (unique on the broker).
    pub client_id: String,
    /// Topic filters subscribed to (at QoS 1) on every connection.
    pub subscriptions: Vec<String>,
    /// A presence topic: retained `online` on every connection, `offline` as the last will
    /// and on [`Link::close`].
    pub presence: Option<String>,
    /// Messages that may wait in the inbox.
    pub inbox: usize,
    /// Tries to reach the broker at the start before giving up (with a doubling wait between,
    /// from 0.1 s up to 2 s).
    pub start_tries: u32,
}

/// What the link hears.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Inbound {
    /// Connected again after a loss (subscriptions and presence renewed).
    Reconnected,
    /// A message on a subscribed topic.
    Message {
        /// Its topic.
        topic: String,
        /// Its payload, as sent.
        payload: Vec<u8>,
    },
    /// The connection was lost (why); the link tries again.
    Lost(String),
}

/// A connected link (see the module documentation).
pub struct Link {
    client: Client,
    inbox: Receiver<Inbound>,
    outbox: VecDeque<(String, Vec<u8>, bool)>,
    dropped: u64,
    presence: Option<String>,
}

impl Link {
    /// Connects (trying `start_tries` times), subscribes, says it is online.
    pub fn connect(options: LinkOptions) -> Result<Link, String> {
        let mut mqtt = MqttOptions::new(&options.client_id, &options.url.host, options.url.port);
        mqtt.set_keep_alive(Duration::from_secs(5));
        mqtt.set_clean_session(true);
        mqtt.set_max_packet_size(MAX_PACKET, MAX_PACKET);
        if let Some(p) = &options.presence {
            mqtt.set_last_will(LastWill::new(p, "offline", QoS::AtLeastOnce, true));
        }
        let (client, mut connection) = Client::new(mqtt, REQUESTS);
        let mut network = connection.eventloop.network_options();
        network.set_tcp_nodelay(true);
        network.set_connection_timeout(5);
        connection.eventloop.set_network_options(network);
        let (tx, inbox) = mpsc::sync_channel(options.inbox.max(1));
        let (ready_tx, ready) = mpsc::channel::<Result<(), String>>();
        let poller = Poller {
            client: client.clone(),
            subscriptions: options.subscriptions.clone(),
            presence: options.presence.clone(),
            tx,
        };
        let tries = options.start_tries.max(1);
        std::thread::spawn(move || poller.run(&mut connection, tries, ready_tx));
        match ready.recv() {
            Ok(Ok(())) => Ok(Link {
                client,
                inbox,
                outbox: VecDeque::new(),
                dropped: 0,
                presence: options.presence,
            }),
            Ok(Err(e)) => Err(format!("cannot reach the broker at {}: {e}", options.url)),
            Err(_) => Err(format!("cannot reach the broker at {}", options.url)),
        }
    }

    /// The next thing heard, waiting at most `wait`.
    pub fn recv_timeout(&self, wait: Duration) -> Option<Inbound> {
        self.inbox.recv_timeout(wait).ok()
    }

    /// What has been heard already, without waiting.
    pub fn try_recv(&self) -> Option<Inbound> {
        self.inbox.try_recv().ok()
    }

    /// Sends `payload` on `topic` at QoS 1 (retained if `retain`): now, or once rumqttc's queue
    /// has room ([`flush`](Self::flush)).
    pub fn publish(&mut self, topic: &str, payload: Vec<u8>, retain: bool) {
        self.flush();
        if self.outbox.is_empty() {
            match self
                .client
                .try_publish(topic, QoS::AtLeastOnce, retain, payload)
            {
                Ok(()) => return,
                Err(e) => {
                    if let Some(m) = unsent(e) {
                        self.keep(m);
                    }
                    return;
                }
            }
        }
        self.keep((topic.to_string(), payload, retain));
    }

    /// Hands what waits in the outbox to rumqttc, as far as its queue has room.
    pub fn flush(&mut self) {
        while let Some((topic, payload, retain)) = self.outbox.pop_front() {
            if let Err(e) = self
                .client
                .try_publish(topic, QoS::AtLeastOnce, retain, payload)
            {
                if let Some(m) = unsent(e) {
                    self.outbox.push_front(m);
                }
                return;
            }
        }
    }

    /// Messages waiting in the outbox.
    pub fn waiting(&self) -> usize {
        self.outbox.len()
    }

    /// How many messages were dropped since last asked (the outbox was full).
    pub fn take_dropped(&mut self) -> u64 {
        std::mem::take(&mut self.dropped)
    }

    /// Says it is offline, hands over what waits (for up to `linger`) and disconnects.
    pub fn close(mut self, linger: Duration) {
        if let Some(p) = self.presence.clone() {
            self.publish(&p, b"offline".to_vec(), true);
        }
        let until = Instant::now() + linger;
        while !self.outbox.is_empty() && Instant::now() < until {
            self.flush();
            std::thread::sleep(Duration::from_millis(5));
        }
        // (what rumqttc still holds goes before the disconnect: its queue is in order)
        let _ = self.client.disconnect();
        std::thread::sleep(linger.min(Duration::from_millis(200)));
    }

    fn keep(&mut self, m: (String, Vec<u8>, bool)) {
        if self.outbox.len() >= OUTBOX_LIMIT {
            self.outbox.pop_front();
            self.dropped += 1;
        }
        self.outbox.push_back(m);
    }
}

/// The message a failed `try_publish` did not send (`None`: it was malformed).
fn unsent(e: ClientError) -> Option<(String, Vec<u8>, bool)> {
    match e {
        ClientError::TryRequest(Request::Publish(p))
        | ClientError::Request(Request::Publish(p)) => {
            Some((p.topic, p.payload.to_vec(), p.retain))
        }
        _ => None,
    }
}

/// The thread that polls the connection.
struct Poller {
    client: Client,
    subscriptions: Vec<String>,
    presence: Option<String>,
    tx: SyncSender<Inbound>,
}

impl Poller {
    fn run(
        self,
        connection: &mut rumqttc::Connection,
        tries: u32,
        ready: mpsc::Sender<Result<(), String>>,
    ) {
        let mut ready = Some(ready);
        let (mut failures, mut lost) = (0u32, false);
        let mut wait = Duration::from_millis(100);
        loop {
            let event = match connection.recv() {
                Ok(e) => e,
                Err(_) => return, // the client is gone
            };
            match event {
                Ok(Event::Incoming(Packet::ConnAck(_))) => {
                    (failures, wait) = (0, Duration::from_millis(100));
                    self.renew();
                    if let Some(r) = ready.take() {
                        let _ = r.send(Ok(()));
                    } else if lost {
                        lost = false;
                        if self.tx.send(Inbound::Reconnected).is_err() {
                            return;
                        }
                    }
                }
                Ok(Event::Incoming(Packet::Publish(p))) => {
                    let m = Inbound::Message {
                        topic: p.topic,
                        payload: p.payload.to_vec(),
                    };
                    if self.tx.send(m).is_err() {
                        return;
                    }
                }
                Ok(_) => {}
                Err(e) => {
                    failures += 1;
                    if ready.is_some() && failures >= tries {
                        let why = format!("{e} ({failures} tries)");
                        let _ = ready.take().map(|r| r.send(Err(why)));
                        return;
                    }
                    if ready.is_none() && !lost {
                        lost = true;
                        if self.tx.send(Inbound::Lost(e.to_string())).is_err() {
                            return;
                        }
                    }
                    std::thread::sleep(wait);
                    wait = (wait * 2).min(Duration::from_secs(2));
                }
            }
        }
    }

    /// Subscribes and says it is online (on every connection).
    fn renew(&self) {
        for s in &self.subscriptions {
            let _ = self.client.try_subscribe(s, QoS::AtLeastOnce);
        }
        if let Some(p) = &self.presence {
            let _ = (self.client).try_publish(p, QoS::AtLeastOnce, true, "online");
        }
    }
}
