//! Splitting a text stream into BML blocks: a stream (stdin, a socket) carries `<bml>` elements
//! one after another, possibly across lines, with `+SECS` clock advances between them. Text that
//! is neither is handed on as garbage, so that it can be reported rather than lost.

use quick_xml::events::Event;
use quick_xml::Reader;

/// One item of a BML stream.
#[derive(Debug, Clone, PartialEq)]
pub enum StreamItem {
    /// The text of one top-level element (normally a `<bml>` block).
    Block(String),
    /// `+SECS`: advance the clock by SECS seconds before the next item.
    Advance(f64),
    /// Text that is neither (reported as a parsing failure).
    Garbage(String),
}

/// Collects text and yields complete items as they become available.
#[derive(Debug, Default)]
pub struct BlockStream {
    buf: String,
}

impl BlockStream {
    /// An empty stream.
    pub fn new() -> Self {
        Self::default()
    }

    /// Appends text read from the source.
    pub fn push(&mut self, text: &str) {
        self.buf.push_str(text);
    }

    /// Whether unread text remains (other than whitespace).
    pub fn has_rest(&self) -> bool {
        !self.buf.trim().is_empty()
    }

    /// The next complete item, if any. With `finished` (no more input will come), an incomplete
    /// element at the end is returned as garbage.
    pub fn next_item(&mut self, finished: bool) -> Option<StreamItem> {
        'skip: loop {
            let trimmed = self.buf.trim_start();
            let skip = self.buf.len() - trimmed.len();
            self.buf.drain(..skip);
            if self.buf.is_empty() {
                return None;
            }
            // declarations and comments between blocks
            for (open, close) in [("<?", "?>"), ("<!--", "-->")] {
                if self.buf.starts_with(open) {
                    match self.buf.find(close) {
                        Some(end) => {
                            self.buf.drain(..end + close.len());
                            continue 'skip;
                        }
                        None if finished => return Some(self.garbage(self.buf.len())),
                        None => return None,
                    }
                }
            }
            break;
        }
        if self.buf.starts_with('+') {
            let end = self.buf.find(char::is_whitespace).unwrap_or(self.buf.len());
            if end == self.buf.len() && !finished {
                return None; // the number may go on
            }
            let token = &self.buf[1..end];
            let item = match token.parse::<f64>() {
                Ok(secs) if secs.is_finite() && secs >= 0.0 => StreamItem::Advance(secs),
                _ => StreamItem::Garbage(self.buf[..end].to_string()),
            };
            self.buf.drain(..end);
            return Some(item);
        }
        if !self.buf.starts_with('<') {
            // up to the next element or advance
            let end = self.buf.find(['<', '\n']).unwrap_or(self.buf.len()).max(1);
            return Some(self.garbage(end));
        }
        match element_end(&self.buf) {
            Some(end) => {
                let text = self.buf[..end].to_string();
                self.buf.drain(..end);
                Some(StreamItem::Block(text))
            }
            None => {
                // incomplete or broken: broken for sure if another block starts after it
                let next = self.buf[1..].find("<bml").map(|i| i + 1);
                match next {
                    Some(n) => Some(self.garbage(n)),
                    None if finished => Some(self.garbage(self.buf.len())),
                    None => None,
                }
            }
        }
    }

    fn garbage(&mut self, end: usize) -> StreamItem {
        let text = self.buf[..end].to_string();
        self.buf.drain(..end);
        StreamItem::Garbage(text)
    }
}

/// The byte length of the first element of `text` (which starts with `<`), if it is complete
/// and well-formed as far as nesting goes.
fn element_end(text: &str) -> Option<usize> {
    let mut reader = Reader::from_str(text);
    let mut depth = 0usize;
    loop {
        match reader.read_event() {
            Ok(Event::Start(_)) => depth += 1,
            Ok(Event::End(_)) => {
                depth = depth.checked_sub(1)?;
                if depth == 0 {
                    return Some(reader.buffer_position() as usize);
                }
            }
            Ok(Event::Empty(_)) if depth == 0 => return Some(reader.buffer_position() as usize),
            Ok(Event::Eof) | Err(_) => return None,
            Ok(_) => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn all(text: &str) -> Vec<StreamItem> {
        let mut s = BlockStream::new();
        s.push(text);
        std::iter::from_fn(|| s.next_item(true)).collect()
    }

    #[test]
    fn blocks_advances_and_garbage_come_out_in_order() {
        let items = all(
            "<?xml version=\"1.0\"?>\n<bml id=\"a\">\n <speech id=\"s\"><text>Hi</text></speech>\n</bml>\n+1.5\n<bml id=\"b\"/>\nhello\n<bml id=\"c\"></bml>",
        );
        assert_eq!(
            items,
            [
                StreamItem::Block(
                    "<bml id=\"a\">\n <speech id=\"s\"><text>Hi</text></speech>\n</bml>".into()
                ),
                StreamItem::Advance(1.5),
                StreamItem::Block("<bml id=\"b\"/>".into()),
                StreamItem::Garbage("hello".into()),
                StreamItem::Block("<bml id=\"c\"></bml>".into()),
            ]
        );
    }

    #[test]
    fn an_incomplete_block_waits_for_more_input() {
        let mut s = BlockStream::new();
        s.push("<bml id=\"a\"><speech id=\"s\"><text>Hi");
        assert_eq!(s.next_item(false), None);
        s.push("</text></speech></bml>+2");
        assert!(matches!(s.next_item(false), Some(StreamItem::Block(_))));
        assert_eq!(s.next_item(false), None); // "+2" may continue
        assert_eq!(s.next_item(true), Some(StreamItem::Advance(2.0)));
    }

    #[test]
    fn a_broken_block_is_garbage_and_the_next_one_still_comes() {
        let items = all("<bml id=\"a\"><speech></bml>\n<bml id=\"b\"/>");
        assert_eq!(items.len(), 2);
        assert!(matches!(&items[0], StreamItem::Garbage(g) if g.contains("<speech>")));
        assert_eq!(items[1], StreamItem::Block("<bml id=\"b\"/>".into()));
        assert_eq!(
            all("+x <bml id=\"b\"/>")[0],
            StreamItem::Garbage("+x".into())
        );
    }
}
