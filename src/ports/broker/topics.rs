//! Topic names and the broker's address. With prefix `bml` (the default): blocks come in on
//! `bml/CHARACTER/bml`, feedback goes out on `bml/CHARACTER/feedback`, a realizer's presence is
//! `bml/realizers/NAME` and a character's root state `bml/world/CELL/CHARACTER` (`CELL` the
//! floor cell it stands in, [`Cell`]). The character `_` is the realizer's default character
//! (blocks without a `characterId`).

use std::fmt;

use super::cells::Cell;

/// The character name in topics of the default character.
pub const DEFAULT_CHARACTER: &str = "_";

/// A broker's address: `mqtt://HOST[:PORT]` (port 1883 when not given).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BrokerUrl {
    /// Host name or address.
    pub host: String,
    /// TCP port.
    pub port: u16,
}

impl BrokerUrl {
    /// Reads `mqtt://HOST[:PORT]` (also `tcp://`); anything else is an error saying why.
    pub fn parse(url: &str) -> Result<BrokerUrl, String> {
        let rest = (url.strip_prefix("mqtt://"))
            .or_else(|| url.strip_prefix("tcp://"))
            .ok_or_else(|| format!("'{url}' is not a broker address (mqtt://HOST[:PORT])"))?;
        let rest = rest.trim_end_matches('/');
        let (host, port) = match rest.rsplit_once(':') {
            // (an IPv6 address in brackets keeps its colons)
            Some((h, p)) if !h.is_empty() && !p.contains(']') => {
                let port = p
                    .parse::<u16>()
                    .ok()
                    .filter(|&p| p > 0)
                    .ok_or_else(|| format!("'{url}': '{p}' is not a port (1 to 65535)"))?;
                (h, port)
            }
            _ => (rest, 1883),
        };
        let host = host.trim_start_matches('[').trim_end_matches(']');
        if host.is_empty() || host.contains('/') {
            return Err(format!("'{url}' names no host (mqtt://HOST[:PORT])"));
        }
        Ok(BrokerUrl {
            host: host.to_string(),
            port,
        })
    }
}

impl fmt::Display for BrokerUrl {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "mqtt://{}:{}", self.host, self.port)
    }
}

/// The topics under one prefix.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Topics {
    prefix: String,
    /// Between levels: `/` on MQTT, `.` on STOMP brokers (ActiveMQ, RabbitMQ).
    sep: char,
    /// The one-level wildcard: `+` on MQTT, `*` on STOMP brokers.
    any: char,
}

impl Topics {
    /// Topics under `prefix` (a topic level or several, without wildcards; `bml` by default).
    pub fn new(prefix: &str) -> Result<Topics, String> {
        let prefix = prefix.trim_matches('/');
        if prefix.is_empty() || prefix.split('/').any(|l| !level_ok(l)) {
            return Err(format!(
                "'{prefix}' is not a topic prefix (levels without '+', '#' or empty ones)"
            ));
        }
        Ok(Topics {
            prefix: prefix.to_string(),
            sep: '/',
            any: '+',
        })
    }

    /// The same names with `.` between levels and `*` as the wildcard, as STOMP brokers name
    /// topics (`bml.world.alice`).
    pub fn dotted(prefix: &str) -> Result<Topics, String> {
        let t = Topics::new(prefix)?;
        if t.prefix.contains('.') || t.prefix.contains('*') {
            return Err(format!("'{prefix}' is not a topic prefix (no '.' or '*')"));
        }
        Ok(Topics {
            prefix: t.prefix.replace('/', "."),
            sep: '.',
            any: '*',
        })
    }

    /// Where blocks for `character` come in.
    pub fn bml(&self, character: &str) -> String {
        format!("{}{s}{character}{s}bml", self.prefix, s = self.sep)
    }

    /// Where `character`'s feedback goes out.
    pub fn feedback(&self, character: &str) -> String {
        format!("{}{s}{character}{s}feedback", self.prefix, s = self.sep)
    }

    /// A realizer's presence (retained `online`; `offline` as its last will).
    pub fn presence(&self, realizer: &str) -> String {
        format!("{}{s}realizers{s}{realizer}", self.prefix, s = self.sep)
    }

    /// Every realizer's presence (a subscription).
    pub fn all_presence(&self) -> String {
        format!("{}{s}realizers{s}{}", self.prefix, self.any, s = self.sep)
    }

    /// Blocks for every character (a subscription).
    pub fn all_bml(&self) -> String {
        format!("{}{s}{}{s}bml", self.prefix, self.any, s = self.sep)
    }

    /// Where the root state of `character`, standing in `cell`, goes (realizers sharing one
    /// world).
    pub fn world(&self, cell: Cell, character: &str) -> String {
        format!(
            "{}{s}world{s}{cell}{s}{character}",
            self.prefix,
            s = self.sep
        )
    }

    /// The root states of every character in `cell` (a subscription).
    pub fn world_cell(&self, cell: Cell) -> String {
        format!(
            "{}{s}world{s}{cell}{s}{}",
            self.prefix,
            self.any,
            s = self.sep
        )
    }

    /// The cell and character a root-state topic is about, if `topic` is one.
    pub fn world_character<'t>(&self, topic: &'t str) -> Option<(Cell, &'t str)> {
        let rest = topic.strip_prefix(&self.prefix)?.strip_prefix(self.sep)?;
        let rest = rest.strip_prefix("world")?.strip_prefix(self.sep)?;
        let (cell, character) = rest.split_once(self.sep)?;
        let ok = level_ok(character) && !character.contains(self.sep);
        Some((Cell::parse(cell)?, character)).filter(|_| ok)
    }

    /// The character a block topic is for, if `topic` is one.
    pub fn bml_character<'t>(&self, topic: &'t str) -> Option<&'t str> {
        let rest = topic.strip_prefix(&self.prefix)?.strip_prefix(self.sep)?;
        let character = rest.strip_suffix("bml")?.strip_suffix(self.sep)?;
        (level_ok(character)
            && !character.contains(self.sep)
            && character != "realizers"
            && character != "world")
            .then_some(character)
    }

    /// The character name in topics of `character` (`None`: the default character).
    pub fn character_level(character: Option<&str>) -> &str {
        character.unwrap_or(DEFAULT_CHARACTER)
    }
}

/// Whether `level` may be a character's or the prefix's topic level.
pub fn level_ok(level: &str) -> bool {
    !level.is_empty() && !level.contains(['/', '+', '#', '\0'])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn broker_addresses_are_read_or_refused_with_the_reason() {
        let u = BrokerUrl::parse("mqtt://127.0.0.1:1884").unwrap();
        assert_eq!((u.host.as_str(), u.port), ("127.0.0.1", 1884));
        assert_eq!(BrokerUrl::parse("mqtt://broker").unwrap().port, 1883);
        assert_eq!(BrokerUrl::parse("tcp://[::1]:7").unwrap().host, "::1");
        assert!(BrokerUrl::parse("http://x")
            .unwrap_err()
            .contains("not a broker"));
        assert!(BrokerUrl::parse("mqtt://x:0")
            .unwrap_err()
            .contains("not a port"));
        assert!(BrokerUrl::parse("mqtt://x:99999")
            .unwrap_err()
            .contains("not a port"));
        assert!(BrokerUrl::parse("mqtt://").unwrap_err().contains("no host"));
    }

    #[test]
    fn topics_name_characters_and_refuse_wildcards() {
        let t = Topics::new("bml").unwrap();
        assert_eq!(t.bml("alice"), "bml/alice/bml");
        assert_eq!(t.feedback("_"), "bml/_/feedback");
        assert_eq!(t.presence("r1"), "bml/realizers/r1");
        assert_eq!(t.bml_character("bml/alice/bml"), Some("alice"));
        assert_eq!(t.bml_character("bml/alice/feedback"), None);
        assert_eq!(t.bml_character("bml/a/b/bml"), None);
        assert_eq!(t.bml_character("bmlx/alice/bml"), None);
        assert_eq!(t.bml_character("bml/realizers/bml"), None);
        let c = Cell { i: -1, j: 2 };
        assert_eq!(t.world(c, "a"), "bml/world/-1_2/a");
        assert_eq!(t.world_cell(c), "bml/world/-1_2/+");
        assert_eq!(t.world_character("bml/world/-1_2/a"), Some((c, "a")));
        assert_eq!(t.world_character("bml/world/a"), None);
        assert_eq!(t.world_character("bml/world/1_2/a/b"), None);
        assert_eq!(t.world_character("bml/world/x/a"), None);
        assert_eq!(t.world_character("bml/a/bml"), None);
        let deep = Topics::new("/site/one/").unwrap();
        assert_eq!(deep.bml("bob"), "site/one/bob/bml");
        assert!(Topics::new("a/+/b").is_err());
        let dotted = Topics::dotted("bml").unwrap();
        assert_eq!(dotted.world(c, "a"), "bml.world.-1_2.a");
        assert_eq!(dotted.world_cell(c), "bml.world.-1_2.*");
        assert_eq!(dotted.presence("r"), "bml.realizers.r");
        assert_eq!(dotted.world_character("bml.world.-1_2.a"), Some((c, "a")));
        assert_eq!(dotted.world_character("bml.world.-1_2.a.b"), None);
        assert!(Topics::dotted("a.b").is_err());
        assert!(Topics::new("").is_err());
    }
}
