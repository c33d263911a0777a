//! Splitting a text stream into BML blocks: a stream (`bmlr run -`) carries `<bml>` elements one
//! after another, possibly across lines, with `+SECS` clock advances between them. Text that is
//! neither is handed on as garbage, so that it can be reported rather than lost, and the stream
//! picks up again at the next line that starts a `<bml>` block: a broken block costs the lines up
//! to the one where it breaks, an unterminated comment or a stray `<![CDATA[`, `<!DOCTYPE` the
//! text up to the next block, and nothing eats a valid block after it.

use super::limits::Limits;
use super::xml::{Event, Problem, Reader};

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
            // declarations and comments between blocks; one that does not end before the next
            // block is garbage up to that block
            for (open, close) in [("<?", "?>"), ("<!--", "-->")] {
                if self.buf.starts_with(open) {
                    let next = next_block(&self.buf);
                    match self.buf.find(close) {
                        Some(end) if next.is_none_or(|n| end < n) => {
                            self.buf.drain(..end + close.len());
                            continue 'skip;
                        }
                        _ => match next {
                            Some(n) => return Some(self.garbage(n)),
                            None if finished => return Some(self.garbage(self.buf.len())),
                            None => return None,
                        },
                    }
                }
            }
            break;
        }
        // CDATA, a DOCTYPE or anything else `<!` between blocks: garbage up to the line's end
        if self.buf.starts_with("<!") {
            return Some(self.garbage(line_end(&self.buf)));
        }
        if self.buf.starts_with('+') {
            let end = self.buf.find(char::is_whitespace).unwrap_or(self.buf.len());
            if end == self.buf.len() && !finished {
                return None; // the number may go on
            }
            let item = match advance(&self.buf[..end]) {
                Some(secs) => StreamItem::Advance(secs),
                None => StreamItem::Garbage(self.buf[..end].to_string()),
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
            Element::Complete(end) => {
                let text = self.buf[..end].to_string();
                self.buf.drain(..end);
                Some(StreamItem::Block(text))
            }
            // broken: it costs the lines up to the one where it breaks
            Element::Broken(at) => {
                let end = at + line_end(&self.buf[at..]);
                Some(self.garbage(end.max(1)))
            }
            // incomplete: broken for sure if a line after it starts another block
            Element::Incomplete => match next_block(&self.buf) {
                Some(n) => Some(self.garbage(n)),
                None if finished => Some(self.garbage(self.buf.len())),
                None => None,
            },
        }
    }

    fn garbage(&mut self, end: usize) -> StreamItem {
        let text = self.buf[..end].to_string();
        self.buf.drain(..end);
        StreamItem::Garbage(text)
    }
}

/// Where the next line that starts a `<bml` block begins (after `text`'s first character).
fn next_block(text: &str) -> Option<usize> {
    let mut at = 0;
    for line in text.split_inclusive('\n') {
        if at > 0 && line.trim_start().starts_with("<bml") {
            return Some(at);
        }
        at += line.len();
    }
    None
}

/// The length of `text` up to and including its first line break (all of it if it has none).
fn line_end(text: &str) -> usize {
    text.find('\n').map_or(text.len(), |i| i + 1)
}

/// How the first element of a text (which starts with `<`) stands.
enum Element {
    /// Complete and well-formed as far as nesting goes: its byte length.
    Complete(usize),
    /// Not well-formed: the byte offset where that shows.
    Broken(usize),
    /// It may go on in text still to come.
    Incomplete,
}

/// Where the first element of `text` ends, read by the same XML reader that parses blocks. A
/// problem inside a tag or text that leaves the structure intact (a bad reference, a name, a
/// limit) does not move the end: the parser reports it for the whole block.
fn element_end(text: &str) -> Element {
    let mut reader = Reader::new(text, &Limits::default());
    let mut depth = 0usize;
    loop {
        match reader.next() {
            Ok(Event::Start(tag)) if tag.empty && depth == 0 => return Element::Complete(tag.end),
            Ok(Event::Start(tag)) if !tag.empty => depth += 1,
            Ok(Event::End { after, .. }) => {
                depth -= 1;
                if depth == 0 {
                    return Element::Complete(after);
                }
            }
            // the text ended inside an element, a tag, comment or CDATA section: more may come
            Ok(Event::Eof) => return Element::Incomplete,
            Err(e) if e.problem == Problem::Unclosed => return Element::Incomplete,
            Err(e) if e.problem == Problem::Broken => return Element::Broken(e.offset),
            Ok(_) | Err(_) => {}
        }
    }
}

/// The seconds of a `+SECS` clock advance (a number ≥ 0), if `token` is one.
pub fn advance(token: &str) -> Option<f64> {
    let secs = token.strip_prefix('+')?.parse::<f64>().ok()?;
    (secs.is_finite() && secs >= 0.0).then_some(secs)
}

/// A line of a port or stream that cannot be read as text.
#[derive(Debug, Clone, PartialEq)]
pub struct BadLine {
    /// Its number, from 1.
    pub line: usize,
    /// What is wrong with it.
    pub reason: String,
}

/// Reads `reader` line by line, as the ports do: each line (without its line break) as text, or
/// a [`BadLine`] for a line that is not UTF-8 or longer than `max_len` bytes (the rest of such a
/// line is skipped, never held). Reading ends at the end of input or at an I/O error; a bad line
/// costs only itself.
pub fn lines<R: std::io::BufRead>(
    mut reader: R,
    max_len: usize,
) -> impl Iterator<Item = Result<String, BadLine>> {
    let mut number = 0;
    std::iter::from_fn(move || {
        let mut buf = Vec::new();
        let read = std::io::BufRead::read_until(
            &mut std::io::Read::take(&mut reader, max_len as u64 + 1),
            b'\n',
            &mut buf,
        );
        if read.ok()? == 0 {
            return None;
        }
        number += 1;
        let ended = buf.last() == Some(&b'\n');
        if !ended && buf.len() > max_len {
            // skip to the end of the line without keeping it
            let mut rest = Vec::new();
            loop {
                let mut chunk = std::io::Read::take(&mut reader, 1 << 16);
                let Ok(n) = std::io::BufRead::read_until(&mut chunk, b'\n', &mut rest) else {
                    break;
                };
                if n == 0 || rest.last() == Some(&b'\n') {
                    break;
                }
                rest.clear();
            }
            let reason = format!("the line is longer than {max_len} bytes (--max-block-bytes)");
            return Some(Err(BadLine {
                line: number,
                reason,
            }));
        }
        while matches!(buf.last(), Some(b'\n' | b'\r')) {
            buf.pop();
        }
        Some(String::from_utf8(buf).map_err(|e| BadLine {
            line: number,
            reason: format!(
                "the line is not UTF-8 (a bad byte at column {})",
                e.utf8_error().valid_up_to() + 1
            ),
        }))
    })
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
    fn bad_text_costs_its_own_lines_and_never_a_valid_block_after_it() {
        let good = "<bml id=\"g\"/>";
        for (bad, garbage) in [
            // a stray comment or declaration opener
            ("<!-- never closed\n", 1),
            ("<?xml never closed\n", 1),
            // a top-level CDATA section
            ("<![CDATA[x]]>\n", 1),
            // a broken block, then a garbage line: two warnings
            ("<bml id=\"a\"><speech></bml>\nhello\n", 2),
            // half a block
            ("<bml id=\"h\"><speech id=\"s\">\n", 1),
        ] {
            let items = all(&format!("{bad}{good}\n{good}"));
            let blocks = items
                .iter()
                .filter(|i| matches!(i, StreamItem::Block(_)))
                .count();
            let bad_items = items
                .iter()
                .filter(|i| matches!(i, StreamItem::Garbage(_)))
                .count();
            assert_eq!((blocks, bad_items), (2, garbage), "{bad:?}: {items:?}");
        }
    }

    #[test]
    fn bad_lines_cost_only_themselves() {
        let input: &[u8] = b"one\n\xff\xfe two\nthree\r\nfour that is far too long\nfive";
        let got: Vec<_> = lines(input, 12).collect();
        assert_eq!(got[0], Ok("one".to_string()));
        assert!(matches!(&got[1], Err(b) if b.line == 2 && b.reason.contains("not UTF-8")));
        assert_eq!(got[2], Ok("three".to_string()));
        assert!(matches!(&got[3], Err(b) if b.line == 4 && b.reason.contains("longer than 12")));
        assert_eq!(got[4], Ok("five".to_string()));
        assert_eq!(got.len(), 5);
    }

    #[test]
    fn a_start_tag_spread_over_lines_waits_for_its_end() {
        let mut s = BlockStream::new();
        s.push("<bml id=\"a\"\n");
        assert_eq!(s.next_item(false), None);
        s.push("  characterId=\"x\"/>\n");
        assert!(matches!(s.next_item(false), Some(StreamItem::Block(_))));
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
