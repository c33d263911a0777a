//! A link to an MQTT broker that keeps itself connected: rumqttc's blocking MQTT 5 client (the
//! protocol ipaacar's components speak too), its connection polled on a thread of its own.
//! Every (re)connection renews the subscriptions and
//! the presence (retained `online`, with `offline` as the last will), since a broker that
//! restarted has forgotten both. What arrives waits in a bounded inbox (the polling thread
//! waits when it is full, and the broker holds back: backpressure; a state heard at QoS 0 is
//! dropped instead and counted, [`Link::states_dropped`], so that polling and the keep-alive go
//! on while the reader falls behind); what is sent goes at QoS 1
//! through an outbox of one lane per topic, handed to rumqttc's small request queue a message
//! of each lane in turn (so that one character's flood of feedback does not hold up another's),
//! at most [`OUTBOX_LIMIT`] messages in all, beyond which the oldest of the longest lane are
//! dropped and counted ([`Link::take_dropped`]). States that a newer one replaces (a
//! character's place, 20 times a second) go at QoS 0 and only the newest of a topic waits
//! ([`Link::publish_state`]); subscriptions to states may change while connected
//! ([`Link::subscribe`], [`Link::unsubscribe`]) and are "no local": the broker does not send a
//! link's own states back to it (MQTT 5 only: under 3.1.1 a realizer listening to the cells its
//! characters stand in heard every state of its own again). TCP_NODELAY is set: without it
//! small messages wait for the
//! previous one's acknowledgement (Nagle's algorithm, ~40 ms stalls).

use std::collections::{BTreeMap, VecDeque};
use std::ops::Bound;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{self, Receiver, SyncSender, TrySendError};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use rumqttc::v5::mqttbytes::v5::{Filter, LastWill, Packet};
use rumqttc::v5::mqttbytes::QoS;
use rumqttc::v5::{Client, ClientError, Connection, Event, MqttOptions, Request};

use super::BrokerUrl;

/// Messages kept while the broker is away, beyond rumqttc's own queue.
pub const OUTBOX_LIMIT: usize = 100_000;

/// Topic filters in one SUBSCRIBE packet when the subscriptions are renewed.
const RENEW_BATCH: usize = 64;

/// rumqttc's request queue (messages handed to its event loop, not yet written): small, so
/// that the lanes of the outbox decide the order.
const REQUESTS: usize = 256;

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
    /// Per topic, what waits to be handed to rumqttc (payload, retain), and the lanes' order
    /// of turns.
    outbox: BTreeMap<String, VecDeque<(Vec<u8>, bool)>>,
    turns: VecDeque<String>,
    waiting: usize,
    dropped: u64,
    presence: Option<String>,
    /// The newest state of each topic not yet handed over, and the topics in the order they
    /// first waited.
    states: BTreeMap<String, Vec<u8>>,
    state_turns: VecDeque<String>,
    /// The subscriptions now (renewed on every connection) and the changes not yet handed
    /// to rumqttc (its queue was full).
    subscriptions: Subscriptions,
    changes: VecDeque<Change>,
    /// States heard (QoS 0) dropped because the inbox was full.
    states_dropped: Arc<AtomicU64>,
}

/// Topic filters subscribed to and at which QoS, shared with the polling thread.
type Subscriptions = Arc<Mutex<BTreeMap<String, QoS>>>;

/// A change of subscription waiting for room in rumqttc's queue.
#[derive(Debug, Clone)]
enum Change {
    Subscribe(String, QoS),
    Unsubscribe(String),
}

impl Link {
    /// Connects (trying `start_tries` times), subscribes, says it is online.
    pub fn connect(options: LinkOptions) -> Result<Link, String> {
        let mut mqtt = MqttOptions::new(&options.client_id, &options.url.host, options.url.port);
        mqtt.set_keep_alive(Duration::from_secs(5));
        mqtt.set_clean_start(true);
        mqtt.set_max_packet_size(Some(MAX_PACKET as u32));
        if let Some(p) = &options.presence {
            mqtt.set_last_will(LastWill::new(p, "offline", QoS::AtLeastOnce, true, None));
        }
        let mut network = mqtt.network_options();
        network.set_tcp_nodelay(true);
        network.set_connection_timeout(5);
        mqtt.set_network_options(network);
        let (client, mut connection) = Client::new(mqtt, REQUESTS);
        let (tx, inbox) = mpsc::sync_channel(options.inbox.max(1));
        let (ready_tx, ready) = mpsc::channel::<Result<(), String>>();
        let subscriptions: Subscriptions = Arc::new(Mutex::new(
            (options.subscriptions.iter())
                .map(|s| (s.clone(), QoS::AtLeastOnce))
                .collect(),
        ));
        let states_dropped = Arc::new(AtomicU64::new(0));
        let poller = Poller {
            client: client.clone(),
            subscriptions: subscriptions.clone(),
            states_dropped: states_dropped.clone(),
            presence: options.presence.clone(),
            tx,
        };
        let tries = options.start_tries.max(1);
        std::thread::spawn(move || poller.run(&mut connection, tries, ready_tx));
        match ready.recv() {
            Ok(Ok(())) => Ok(Link {
                client,
                inbox,
                outbox: BTreeMap::new(),
                turns: VecDeque::new(),
                waiting: 0,
                dropped: 0,
                presence: options.presence,
                states: BTreeMap::new(),
                state_turns: VecDeque::new(),
                subscriptions,
                changes: VecDeque::new(),
                states_dropped,
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

    /// Sends `payload` on `topic` at QoS 1 (retained if `retain`), after what waits on the same
    /// topic; hands what it can to rumqttc ([`flush`](Self::flush)).
    pub fn publish(&mut self, topic: &str, payload: Vec<u8>, retain: bool) {
        if self.waiting >= OUTBOX_LIMIT {
            self.drop_oldest();
        }
        match self.outbox.get_mut(topic) {
            Some(lane) => lane.push_back((payload, retain)),
            None => {
                self.outbox
                    .insert(topic.to_string(), VecDeque::from([(payload, retain)]));
                // (a lane emptied by a drop may still have its turn)
                if !self.turns.iter().any(|t| t == topic) {
                    self.turns.push_back(topic.to_string());
                }
            }
        }
        self.waiting += 1;
        self.flush();
    }

    /// Sends `payload` on `topic` at QoS 0, replacing what waits on that topic: a state that
    /// the next one makes old (lost on the way, the next one comes).
    pub fn publish_state(&mut self, topic: &str, payload: Vec<u8>) {
        if self.states.insert(topic.to_string(), payload).is_none() {
            self.state_turns.push_back(topic.to_string());
        }
        self.flush();
    }

    /// Subscribes to `filter` at QoS 0 (now and on every connection after), if not already:
    /// states that the next one makes old.
    pub fn subscribe(&mut self, filter: &str) {
        let mut now = self.subscriptions.lock().unwrap_or_else(|e| e.into_inner());
        if now.insert(filter.to_string(), QoS::AtMostOnce).is_none() {
            drop(now);
            self.changes
                .push_back(Change::Subscribe(filter.to_string(), QoS::AtMostOnce));
            self.flush();
        }
    }

    /// Ends the subscription to `filter`.
    pub fn unsubscribe(&mut self, filter: &str) {
        let mut now = self.subscriptions.lock().unwrap_or_else(|e| e.into_inner());
        if now.remove(filter).is_some() {
            drop(now);
            self.changes
                .push_back(Change::Unsubscribe(filter.to_string()));
            self.flush();
        }
    }

    /// Hands waiting changes of subscription, messages (a message of each topic in turn) and
    /// then states to rumqttc, as far as its queue has room.
    pub fn flush(&mut self) {
        while let Some(change) = self.changes.pop_front() {
            let handed = match &change {
                Change::Subscribe(f, qos) => self.client.try_subscribe_many([filter(f, *qos)]),
                Change::Unsubscribe(f) => self.client.try_unsubscribe(f),
            };
            if handed.is_err() {
                self.changes.push_front(change);
                return;
            }
        }
        if self.flush_messages() {
            self.flush_states();
        }
    }

    /// Hands over the newest states, oldest waiting first; false when rumqttc is full.
    fn flush_states(&mut self) {
        while let Some(topic) = self.state_turns.pop_front() {
            let Some(payload) = self.states.remove(&topic) else {
                continue;
            };
            if let Err(e) = (self.client).try_publish(&topic, QoS::AtMostOnce, false, payload) {
                if let Some((_, payload, _)) = unsent(e) {
                    self.states.insert(topic.clone(), payload);
                    self.state_turns.push_front(topic);
                }
                return;
            }
        }
    }

    /// Hands over waiting messages a topic in turn; false when rumqttc is full.
    fn flush_messages(&mut self) -> bool {
        while let Some(topic) = self.turns.pop_front() {
            let Some(lane) = self.outbox.get_mut(&topic) else {
                continue;
            };
            let Some((payload, retain)) = lane.pop_front() else {
                self.outbox.remove(&topic);
                continue;
            };
            match (self.client).try_publish(topic.clone(), QoS::AtLeastOnce, retain, payload) {
                Ok(()) => {
                    self.waiting -= 1;
                    if lane.is_empty() {
                        self.outbox.remove(&topic);
                    } else {
                        self.turns.push_back(topic);
                    }
                }
                Err(e) => {
                    // full: it goes first next time
                    match unsent(e) {
                        Some((_, payload, retain)) => lane.push_front((payload, retain)),
                        None => self.waiting -= 1,
                    }
                    if lane.is_empty() {
                        self.outbox.remove(&topic);
                    } else {
                        self.turns.push_front(topic);
                    }
                    return false;
                }
            }
        }
        true
    }

    /// States heard (QoS 0 messages) dropped so far because the inbox was full: the loop
    /// reading it fell behind.
    pub fn states_dropped(&self) -> u64 {
        self.states_dropped.load(Ordering::Relaxed)
    }

    /// Messages waiting in the outbox.
    pub fn waiting(&self) -> usize {
        self.waiting
    }

    /// Drops the oldest message of the longest lane (the outbox is full).
    fn drop_oldest(&mut self) {
        let longest = (self.outbox.iter())
            .max_by_key(|(_, lane)| lane.len())
            .map(|(t, _)| t.clone());
        if let Some(lane) = longest.and_then(|t| self.outbox.get_mut(&t)) {
            if lane.pop_front().is_some() {
                self.waiting -= 1;
                self.dropped += 1;
            }
        }
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
        while (self.waiting > 0 || !self.states.is_empty()) && Instant::now() < until {
            self.flush();
            std::thread::sleep(Duration::from_millis(5));
        }
        // (what rumqttc still holds goes before the disconnect: its queue is in order)
        let _ = self.client.disconnect();
        std::thread::sleep(linger.min(Duration::from_millis(200)));
    }
}

/// The filter subscribed to for `path` at `qos`: one at QoS 0 listens to states, and the broker
/// sends none of this link's own back ("no local").
fn filter(path: &str, qos: QoS) -> Filter {
    Filter {
        nolocal: qos == QoS::AtMostOnce,
        ..Filter::new(path, qos)
    }
}

/// The message a failed `try_publish` did not send (`None`: it was malformed).
fn unsent(e: ClientError) -> Option<(String, Vec<u8>, bool)> {
    match e {
        ClientError::TryRequest(Request::Publish(p))
        | ClientError::Request(Request::Publish(p)) => Some((
            String::from_utf8_lossy(&p.topic).into_owned(),
            p.payload.to_vec(),
            p.retain,
        )),
        _ => None,
    }
}

/// The thread that polls the connection.
struct Poller {
    client: Client,
    subscriptions: Subscriptions,
    presence: Option<String>,
    tx: SyncSender<Inbound>,
    states_dropped: Arc<AtomicU64>,
}

impl Poller {
    fn run(self, connection: &mut Connection, tries: u32, ready: mpsc::Sender<Result<(), String>>) {
        let mut ready = Some(ready);
        let (mut failures, mut lost) = (0u32, false);
        let mut wait = Duration::from_millis(100);
        // (renewed at each connection; tried again while rumqttc's queue is full of what
        // waited to be sent)
        let (mut renewing, mut renewed) = (false, None);
        loop {
            if renewing {
                renewing = !self.renew(&mut renewed);
            }
            let event = match connection.recv() {
                Ok(e) => e,
                Err(_) => return, // the client is gone
            };
            match event {
                Ok(Event::Incoming(Packet::ConnAck(_))) => {
                    (failures, wait) = (0, Duration::from_millis(100));
                    renewed = None;
                    renewing = !self.renew(&mut renewed);
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
                    let qos = p.qos;
                    let m = Inbound::Message {
                        topic: String::from_utf8_lossy(&p.topic).into_owned(),
                        payload: p.payload.to_vec(),
                    };
                    // a state (QoS 0) the next one makes old is dropped when the inbox is
                    // full, rather than stop polling: the connection's keep-alive goes on
                    let sent = match qos {
                        QoS::AtMostOnce => match self.tx.try_send(m) {
                            Err(TrySendError::Disconnected(_)) => Err(()),
                            Err(TrySendError::Full(_)) => {
                                self.states_dropped.fetch_add(1, Ordering::Relaxed);
                                Ok(())
                            }
                            Ok(()) => Ok(()),
                        },
                        _ => self.tx.send(m).map_err(|_| ()),
                    };
                    if sent.is_err() {
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

    /// Subscribes and says it is online (on every connection), [`RENEW_BATCH`] filters a
    /// packet, in order from the filter after `renewed` (the last one handed on; none at
    /// first); false when rumqttc's queue had no room for all of it. It goes on from where it
    /// stopped: a queue smaller than the filters would otherwise be filled with the first ones
    /// again and again. (Resuming after a name, not a count, skips none when filters were
    /// added or dropped in between; subscribing again to a topic is harmless.)
    fn renew(&self, renewed: &mut Option<String>) -> bool {
        let after = match renewed.as_deref() {
            Some(last) => (Bound::Excluded(last), Bound::Unbounded),
            None => (Bound::Unbounded, Bound::Unbounded),
        };
        let filters: Vec<Filter> = (self.subscriptions.lock())
            .unwrap_or_else(|e| e.into_inner())
            .range::<str, _>(after)
            .map(|(path, qos)| filter(path, *qos))
            .collect();
        for batch in filters.chunks(RENEW_BATCH) {
            if self.client.try_subscribe_many(batch.to_vec()).is_err() {
                return false;
            }
            *renewed = batch.last().map(|f| f.path.clone());
        }
        self.presence.as_ref().is_none_or(|p| {
            (self.client)
                .try_publish(p, QoS::AtLeastOnce, true, "online")
                .is_ok()
        })
    }
}
