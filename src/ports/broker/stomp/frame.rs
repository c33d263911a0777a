//! STOMP 1.2 frames (stomp.github.io, "STOMP Protocol Specification, Version 1.2"): a command
//! line, header lines `name:value`, a blank line, the body and a NUL octet. Header names and
//! values escape `\r`, `\n`, `:` and `\` as `\r`, `\n`, `\c` and `\\` (except in the CONNECT and
//! CONNECTED frames); a body may be measured by `content-length`, else it ends at the first
//! NUL. Between frames a peer may send end-of-lines as heart-beats.
//!
//! Frames that this realizer sends carry no `content-length`: ActiveMQ hands a STOMP message
//! without one to JMS clients as a `TextMessage` (with one, as a `BytesMessage`), and the peers'
//! JMS code (AsapRealizer's, Greta's) only reads text messages. A body with a NUL octet cannot
//! travel that way and is refused.

/// The largest frame taken (bytes); a larger one ends the connection.
pub const MAX_FRAME: usize = 16 << 20;

/// One frame.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Frame {
    /// The command (`SEND`, `MESSAGE`, …).
    pub command: String,
    /// Headers in order (the first of a repeated name counts).
    pub headers: Vec<(String, String)>,
    /// The body.
    pub body: Vec<u8>,
}

impl Frame {
    /// A frame of `command` with `headers` and no body.
    pub fn new(command: &str, headers: &[(&str, &str)]) -> Frame {
        Frame {
            command: command.into(),
            headers: (headers.iter())
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect(),
            body: Vec::new(),
        }
    }

    /// The first value of header `name`.
    pub fn header(&self, name: &str) -> Option<&str> {
        (self.headers.iter())
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }

    /// The frame on the wire.
    pub fn encode(&self) -> Vec<u8> {
        let raw = matches!(self.command.as_str(), "CONNECT" | "CONNECTED" | "STOMP");
        let mut out = Vec::with_capacity(self.body.len() + 64);
        out.extend_from_slice(self.command.as_bytes());
        out.push(b'\n');
        for (k, v) in &self.headers {
            if raw {
                out.extend_from_slice(k.as_bytes());
                out.push(b':');
                out.extend_from_slice(v.as_bytes());
            } else {
                escape(k, &mut out);
                out.push(b':');
                escape(v, &mut out);
            }
            out.push(b'\n');
        }
        out.push(b'\n');
        out.extend_from_slice(&self.body);
        out.push(0);
        out
    }
}

fn escape(s: &str, out: &mut Vec<u8>) {
    for b in s.bytes() {
        match b {
            b'\\' => out.extend_from_slice(b"\\\\"),
            b'\n' => out.extend_from_slice(b"\\n"),
            b'\r' => out.extend_from_slice(b"\\r"),
            b':' => out.extend_from_slice(b"\\c"),
            b => out.push(b),
        }
    }
}

fn unescape(s: &str) -> Result<String, String> {
    let mut out = String::with_capacity(s.len());
    let mut chars = s.chars();
    while let Some(c) = chars.next() {
        if c != '\\' {
            out.push(c);
            continue;
        }
        match chars.next() {
            Some('\\') => out.push('\\'),
            Some('n') => out.push('\n'),
            Some('r') => out.push('\r'),
            Some('c') => out.push(':'),
            other => {
                return Err(format!(
                    "undefined escape '\\{}' in a header",
                    other.unwrap_or(' ')
                ))
            }
        }
    }
    Ok(out)
}

/// Reads frames out of a byte stream as it arrives.
#[derive(Debug, Default)]
pub struct Decoder {
    buf: Vec<u8>,
}

/// What the decoder found at the front of its buffer.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Decoded {
    /// A whole frame.
    Frame(Frame),
    /// A heart-beat (an end-of-line between frames).
    HeartBeat,
}

impl Decoder {
    /// Adds bytes read from the connection.
    pub fn push(&mut self, bytes: &[u8]) {
        self.buf.extend_from_slice(bytes);
    }

    /// The next frame or heart-beat, `Ok(None)` when more bytes are needed, `Err` when the
    /// stream is not STOMP (the connection should end).
    pub fn take(&mut self) -> Result<Option<Decoded>, String> {
        match self.buf.first() {
            None => return Ok(None),
            Some(b'\n') => {
                self.buf.drain(..1);
                return Ok(Some(Decoded::HeartBeat));
            }
            Some(b'\r') if self.buf.get(1) == Some(&b'\n') => {
                self.buf.drain(..2);
                return Ok(Some(Decoded::HeartBeat));
            }
            Some(b'\r') if self.buf.len() < 2 => return Ok(None),
            _ => {}
        }
        // the head ends at the first blank line
        let Some(head_end) = find(&self.buf, b"\n\n")
            .map(|i| (i, i + 2))
            .into_iter()
            .chain(find(&self.buf, b"\r\n\r\n").map(|i| (i, i + 4)))
            .min_by_key(|(i, _)| *i)
        else {
            if self.buf.len() > MAX_FRAME {
                return Err(format!("a frame's head longer than {MAX_FRAME} bytes"));
            }
            return Ok(None);
        };
        let head = std::str::from_utf8(&self.buf[..head_end.0])
            .map_err(|_| "a frame's head is not UTF-8".to_string())?;
        let mut lines = head.split('\n').map(|l| l.strip_suffix('\r').unwrap_or(l));
        let command = lines.next().unwrap_or_default().to_string();
        // (STOMP's commands are words in capitals)
        if command.is_empty() || !command.bytes().all(|b| b.is_ascii_uppercase()) {
            return Err(format!(
                "'{}' is not a STOMP command",
                command.escape_debug()
            ));
        }
        let raw = matches!(command.as_str(), "CONNECT" | "CONNECTED" | "STOMP");
        let mut headers = Vec::new();
        for line in lines {
            let (k, v) = line
                .split_once(':')
                .ok_or_else(|| format!("a header line without ':' in {command}"))?;
            if raw && line.contains('\r') {
                // (unescaped headers cannot say a carriage return: it would end the line)
                return Err(format!("a carriage return inside a header of {command}"));
            }
            if raw {
                headers.push((k.to_string(), v.to_string()));
            } else {
                headers.push((unescape(k)?, unescape(v)?));
            }
        }
        let body_start = head_end.1;
        let length = (headers.iter())
            .find(|(k, _)| k == "content-length")
            .map(|(_, v)| v.trim().parse::<usize>())
            .transpose()
            .map_err(|_| "content-length is not a number".to_string())?;
        let body_end = match length {
            Some(n) if n > MAX_FRAME => {
                return Err(format!("a body of {n} bytes (more than {MAX_FRAME})"))
            }
            Some(n) if self.buf.len() < body_start + n + 1 => return Ok(None),
            Some(n) if self.buf[body_start + n] != 0 => {
                return Err("a body not followed by NUL".into())
            }
            Some(n) => body_start + n,
            None => match memchr::memchr(0, &self.buf[body_start..]) {
                Some(i) => body_start + i,
                None if self.buf.len() > MAX_FRAME => {
                    return Err(format!("a frame longer than {MAX_FRAME} bytes"))
                }
                None => return Ok(None),
            },
        };
        let body = self.buf[body_start..body_end].to_vec();
        self.buf.drain(..body_end + 1);
        Ok(Some(Decoded::Frame(Frame {
            command,
            headers,
            body,
        })))
    }
}

fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    memchr::memmem::find(hay, needle)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn decode_all(bytes: &[u8]) -> Vec<Decoded> {
        let mut d = Decoder::default();
        let mut out = Vec::new();
        // byte by byte: a frame split anywhere is still read whole
        for b in bytes {
            d.push(&[*b]);
            while let Some(x) = d.take().unwrap() {
                out.push(x);
            }
        }
        out
    }

    #[test]
    fn frames_round_trip_with_escaped_headers_split_anywhere() {
        let mut f = Frame::new(
            "SEND",
            &[("destination", "/topic/a"), ("odd:name", "a\nb\\c")],
        );
        f.body = b"<bml id=\"x\"/>".to_vec();
        let wire = f.encode();
        assert!(wire.starts_with(b"SEND\ndestination:/topic/a\nodd\\cname:a\\nb\\\\c\n\n<bml"));
        let mut twice = wire.clone();
        twice.extend_from_slice(b"\n\r\n");
        twice.extend_from_slice(&wire);
        let got = decode_all(&twice);
        assert_eq!(
            got,
            [
                Decoded::Frame(f.clone()),
                Decoded::HeartBeat,
                Decoded::HeartBeat,
                Decoded::Frame(f)
            ]
        );
    }

    #[test]
    fn content_length_bodies_may_hold_nul_and_connect_headers_are_not_escaped() {
        let wire = b"MESSAGE\ncontent-length:3\ndestination:/topic/x\n\na\0b\0";
        let got = decode_all(wire);
        let Decoded::Frame(f) = &got[0] else { panic!() };
        assert_eq!(
            (f.body.as_slice(), f.header("destination")),
            (&b"a\0b"[..], Some("/topic/x"))
        );
        let c = decode_all(b"CONNECTED\r\nversion:1.2\r\nserver:x\\y\r\n\r\n\0");
        let Decoded::Frame(c) = &c[0] else { panic!() };
        assert_eq!(c.header("server"), Some("x\\y"));
    }

    #[test]
    fn garbage_is_an_error_not_a_hang() {
        let mut d = Decoder::default();
        d.push(b"SEND\nno colon here\n\n\0");
        assert!(d.take().is_err());
        let mut d = Decoder::default();
        d.push(b"MESSAGE\nx:\\q\n\n\0");
        assert!(d.take().is_err());
        let mut d = Decoder::default();
        d.push(b"MESSAGE\ncontent-length:2\n\nabc\0");
        assert!(d.take().is_err());
        // (found by the broker fuzz target: neither can be written back as it was read)
        for garbage in [
            &b"MESSAGE\r\r\n\n\0"[..],
            b"CONNECTED\nversion:1.2\r\r\n\n\0",
        ] {
            let mut d = Decoder::default();
            d.push(garbage);
            assert!(d.take().is_err(), "{garbage:?}");
        }
    }
}
