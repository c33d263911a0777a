//! Timing marks that come with a recorded or cloud-synthesized sound, in the three forms voices
//! give them, recognised by content: Amazon Polly's speech marks (JSON lines, one object a line:
//! `{"time": ms, "type": "word" | "viseme" | "sentence" | "ssml", "start", "end", "value"}`), a
//! word list (`[{"word": "hello", "start": 0.12, "end": 0.45}]`, seconds; `text` for `word` is
//! taken too), or WebVTT (`WEBVTT`, then cues `00:00:00.120 --> 00:00:00.450` whose text is the
//! word). Polly's visemes become the phone of the realizer's that looks like them, so the lips
//! follow them through the same coarticulation as a TTS's phones. Errors name the file and line.

use super::Word;

/// The marks read from a file.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Marks {
    /// The words in order; a word without an end (Polly gives only starts) ends where the next
    /// begins, the last at the sound's end.
    pub words: Vec<Word>,
    /// Polly's viseme marks: when each starts and the realizer phone that looks like it.
    pub visemes: Vec<(f64, &'static str)>,
    /// Polly's `ssml` marks (`<mark name="…"/>`): name and time.
    pub named: Vec<(String, f64)>,
    /// Which form they came in.
    pub form: Form,
}

/// A form of timing marks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Form {
    /// Amazon Polly speech marks (JSON lines, milliseconds).
    #[default]
    Polly,
    /// A JSON list of words with start and end (seconds).
    WordList,
    /// WebVTT cues, one word each.
    WebVtt,
}

/// How many marks a file may hold.
pub const MAX_MARKS: usize = 100_000;

/// A word's end not known yet (Polly marks give starts only).
const OPEN: f64 = f64::NAN;

/// The marks in `text` (read from `file`, which errors name).
pub fn parse(text: &str, file: &str) -> Result<Marks, String> {
    let start = text.trim_start_matches('\u{feff}').trim_start();
    let mut marks = if start.starts_with("WEBVTT") {
        webvtt(text, file)?
    } else if start.starts_with('[') {
        word_list(text, file)?
    } else if start.starts_with('{') {
        polly(text, file)?
    } else {
        return Err(format!(
            "{file}: line 1: not timing marks (Polly speech marks are JSON objects one a line, a word list is a JSON list, WebVTT starts with WEBVTT)"
        ));
    };
    if marks.words.len() + marks.visemes.len() > MAX_MARKS {
        return Err(format!("{file}: more than {MAX_MARKS} marks"));
    }
    marks.words.sort_by(|a, b| a.start.total_cmp(&b.start));
    marks.visemes.sort_by(|a, b| a.0.total_cmp(&b.0));
    // a word without an end ends where the next one starts (the last stays open)
    for i in 1..marks.words.len() {
        let next = marks.words[i].start;
        let w = &mut marks.words[i - 1];
        if w.end.is_nan() {
            w.end = next;
        }
    }
    Ok(marks)
}

/// A time that must be a finite number of seconds, not negative.
fn seconds(value: f64, file: &str, line: usize, what: &str) -> Result<f64, String> {
    if (0.0..1e7).contains(&value) {
        Ok(value)
    } else {
        Err(format!("{file}: line {line}: {what} {value} is not a time"))
    }
}

fn polly(text: &str, file: &str) -> Result<Marks, String> {
    let mut marks = Marks {
        form: Form::Polly,
        ..Marks::default()
    };
    for (n, line) in text.lines().enumerate().map(|(n, l)| (n + 1, l.trim())) {
        if line.is_empty() {
            continue;
        }
        let v: serde_json::Value = serde_json::from_str(line)
            .map_err(|e| format!("{file}: line {n}: not a JSON object: {e}"))?;
        let field = |name: &str| v.get(name);
        let time = field("time")
            .and_then(serde_json::Value::as_f64)
            .ok_or_else(|| format!("{file}: line {n}: a speech mark needs a \"time\" in ms"))?;
        let time = seconds(time / 1000.0, file, n, "time")?;
        let value = field("value").and_then(|x| x.as_str()).unwrap_or("");
        match field("type").and_then(|x| x.as_str()) {
            Some("word") => marks.words.push(Word {
                text: value.to_string(),
                start: time,
                end: OPEN,
            }),
            Some("viseme") => marks.visemes.push((time, polly_viseme(value))),
            Some("ssml") => marks.named.push((value.to_string(), time)),
            Some("sentence") => {}
            other => {
                return Err(format!(
                "{file}: line {n}: a speech mark's type is word, viseme, sentence or ssml, not {}",
                other.map_or("missing".to_string(), |t| format!("{t:?}"))
            ))
            }
        }
    }
    Ok(marks)
}

/// The realizer phone that looks like Polly viseme `v` (Polly's viseme tables: `p` for p b m,
/// `t` for t d n, `S` for the postalveolars, `T` for the dentals, `f` for f v, `k` for k g ŋ
/// h, `s` for s z, `r`, `l`, and the vowels `a` (æ ɑ), `@` (ə ʌ), `e` (eɪ ɛ), `E` (ɝ), `i` (i
/// ɪ j), `o` (oʊ), `O` (ɔ), `u` (u ʊ w); `B` the bilabial fricative, `sil` silence).
pub fn polly_viseme(v: &str) -> &'static str {
    match v {
        "p" | "B" => "P",
        "t" => "T",
        "S" | "J" => "SH",
        "T" => "TH",
        "f" => "F",
        "k" => "K",
        "s" | "z" => "S",
        "r" => "R",
        "l" => "L",
        "a" => "AA",
        "@" => "AH",
        "e" => "EH",
        "E" => "ER",
        "i" => "IY",
        "o" => "OW",
        "O" => "AO",
        "u" => "UW",
        _ => "pau",
    }
}

fn word_list(text: &str, file: &str) -> Result<Marks, String> {
    let list: Vec<serde_json::Value> = serde_json::from_str(text).map_err(|e| {
        format!(
            "{file}: line {}: not a JSON list of words: {e}",
            e.line().max(1)
        )
    })?;
    let mut marks = Marks {
        form: Form::WordList,
        ..Marks::default()
    };
    for (i, item) in list.iter().enumerate() {
        let at = |what: &str| format!("{file}: word {}: {what}", i + 1);
        let word = (item.get("word").or_else(|| item.get("text")))
            .and_then(|x| x.as_str())
            .ok_or_else(|| at("needs a \"word\""))?;
        let time = |name: &str| {
            let t = (item.get(name).and_then(serde_json::Value::as_f64))
                .ok_or_else(|| at(&format!("needs a \"{name}\" in seconds")))?;
            if t.is_finite() && (0.0..1e7).contains(&t) {
                Ok(t)
            } else {
                Err(at(&format!("{name} {t} is not a time")))
            }
        };
        let (start, end) = (time("start")?, time("end")?);
        if end < start {
            return Err(at(&format!("ends ({end}) before it starts ({start})")));
        }
        marks.words.push(Word {
            text: word.to_string(),
            start,
            end,
        });
    }
    Ok(marks)
}

/// A WebVTT timestamp (`hh:mm:ss.ttt` or `mm:ss.ttt`) in seconds.
fn vtt_time(s: &str) -> Option<f64> {
    let parts: Vec<&str> = s.trim().split(':').collect();
    let (h, m, sec) = match parts.as_slice() {
        [h, m, s] => (h.parse::<f64>().ok()?, m.parse::<f64>().ok()?, *s),
        [m, s] => (0.0, m.parse::<f64>().ok()?, *s),
        _ => return None,
    };
    let sec: f64 = sec.parse().ok()?;
    Some(h * 3600.0 + m * 60.0 + sec)
}

fn webvtt(text: &str, file: &str) -> Result<Marks, String> {
    let mut marks = Marks {
        form: Form::WebVtt,
        ..Marks::default()
    };
    let mut lines = text.lines().enumerate().map(|(n, l)| (n + 1, l.trim()));
    let mut cue: Option<(usize, f64, f64, String)> = None;
    let mut finish = |cue: &mut Option<(usize, f64, f64, String)>| {
        if let Some((_, start, end, words)) = cue.take() {
            let words = strip_tags(&words);
            if !words.trim().is_empty() {
                marks.words.push(Word {
                    text: words.trim().to_string(),
                    start,
                    end,
                });
            }
        }
    };
    lines.next(); // WEBVTT
    for (n, line) in lines {
        if let Some((from, rest)) = line.split_once("-->") {
            finish(&mut cue);
            let to = rest.split_whitespace().next().unwrap_or("");
            let (Some(a), Some(b)) = (vtt_time(from), vtt_time(to)) else {
                return Err(format!("{file}: line {n}: a cue's times are hh:mm:ss.ttt --> hh:mm:ss.ttt, not {line:?}"));
            };
            let (a, b) = (seconds(a, file, n, "start")?, seconds(b, file, n, "end")?);
            if b < a {
                return Err(format!("{file}: line {n}: the cue ends before it starts"));
            }
            cue = Some((n, a, b, String::new()));
        } else if line.is_empty() {
            finish(&mut cue);
        } else if let Some((_, _, _, words)) = cue.as_mut() {
            if !words.is_empty() {
                words.push(' ');
            }
            words.push_str(line);
        }
    }
    finish(&mut cue);
    Ok(marks)
}

/// Text without WebVTT's `<…>` tags (voice spans, timestamps inside a cue).
fn strip_tags(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    let mut inside = false;
    for c in s.chars() {
        match c {
            '<' => inside = true,
            '>' => inside = false,
            c if !inside => out.push(c),
            _ => {}
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polly_marks_give_words_visemes_and_named_marks() {
        let text = r#"{"time":0,"type":"sentence","start":0,"end":12,"value":"Hi big Mary."}
{"time":6,"type":"word","start":0,"end":2,"value":"Hi"}
{"time":6,"type":"viseme","value":"k"}
{"time":80,"type":"viseme","value":"a"}
{"time":250,"type":"ssml","start":3,"end":20,"value":"s1"}
{"time":250,"type":"word","start":3,"end":6,"value":"big"}
{"time":250,"type":"viseme","value":"p"}
{"time":600,"type":"word","start":7,"end":11,"value":"Mary"}
"#;
        let m = parse(text, "m.marks").unwrap();
        assert_eq!(m.form, Form::Polly);
        let words: Vec<_> = m.words.iter().map(|w| (w.text.as_str(), w.start)).collect();
        assert_eq!(words, [("Hi", 0.006), ("big", 0.25), ("Mary", 0.6)]);
        assert_eq!(m.words[0].end, 0.25);
        assert!(m.words[2].end.is_nan(), "the last word ends with the sound");
        assert_eq!(m.visemes[2], (0.25, "P"));
        assert_eq!(m.named, [("s1".to_string(), 0.25)]);
    }

    #[test]
    fn word_lists_and_webvtt() {
        let list = r#"[{"word": "hello", "start": 0.12, "end": 0.45}, {"text": "there", "start": 0.5, "end": 0.9}]"#;
        let m = parse(list, "w.json").unwrap();
        assert_eq!(m.form, Form::WordList);
        assert_eq!(m.words[1].text, "there");
        assert_eq!((m.words[1].start, m.words[1].end), (0.5, 0.9));
        let vtt = "WEBVTT\n\n1\n00:00:00.120 --> 00:00:00.450\nhello\n\n00:00.500 --> 00:00.900 align:start\n<v Bob>there</v>\n";
        let m = parse(vtt, "w.vtt").unwrap();
        assert_eq!(m.form, Form::WebVtt);
        let words: Vec<_> = (m.words.iter())
            .map(|w| (w.text.as_str(), w.start, w.end))
            .collect();
        assert_eq!(words, [("hello", 0.12, 0.45), ("there", 0.5, 0.9)]);
    }

    #[test]
    fn bad_marks_name_the_file_and_line() {
        let e = parse(
            "{\"time\":0,\"type\":\"word\",\"value\":\"a\"}\n{\"time\": \"x\"}\n",
            "m.marks",
        )
        .unwrap_err();
        assert!(e.starts_with("m.marks: line 2:"), "{e}");
        let e = parse(
            "WEBVTT\n\n00:00.5 -> 00:01.0\nhi\n00:xx.0 --> 00:01.0\n",
            "w.vtt",
        )
        .unwrap_err();
        assert!(e.starts_with("w.vtt: line 5:"), "{e}");
        let e = parse("[{\"word\": \"a\", \"start\": 1, \"end\": 0.5}]", "w.json").unwrap_err();
        assert!(e.contains("w.json: word 1: ends"), "{e}");
        assert!(parse("hello", "x.txt")
            .unwrap_err()
            .starts_with("x.txt: line 1:"));
        let e = parse("{\"time\":-5,\"type\":\"word\",\"value\":\"a\"}", "m").unwrap_err();
        assert!(e.contains("not a time"), "{e}");
    }
}
