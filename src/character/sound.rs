//! Sound: what plays in a frame (speech a TTS synthesized, `bmlt:audiofile` clips), the
//! start/stop events a host that plays sound itself listens to, and the mix of a whole run into
//! one WAV (`bmlr run --wav`): every clip placed sample-accurately at its peg, at its volume,
//! resampled linearly to the output rate, cut with a 10 ms fade where it was stopped early
//! (an interrupt), summed and clamped to 16 bits.

use std::sync::Arc;

/// Audio: mono 16-bit samples at a rate (what a voice synthesizes, a clip holds, a run mixes).
#[derive(Debug, Clone, PartialEq)]
pub struct Audio {
    /// Samples per second.
    pub rate: u32,
    /// 16-bit samples.
    pub samples: Vec<i16>,
}

/// A sound playing in a frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Playing {
    /// What plays it: `block:behaviour`.
    pub id: String,
    /// The global time of its first sample.
    pub start: f64,
    /// When it stops (global): its end, or earlier when it was interrupted.
    pub stop: f64,
    /// Volume, 0–1.
    pub volume: f32,
    /// The samples.
    pub audio: Arc<Audio>,
}

impl Playing {
    /// The clip's own length (seconds).
    pub fn length(&self) -> f64 {
        self.audio.samples.len() as f64 / f64::from(self.audio.rate.max(1))
    }
}

/// A sound starting or stopping, for hosts that play sound themselves.
#[derive(Debug, Clone, PartialEq)]
pub struct SoundEvent {
    /// Started (`true`) or stopped.
    pub start: bool,
    /// What plays it: `block:behaviour`.
    pub id: String,
    /// How far into the clip (seconds).
    pub offset: f64,
}

/// The fade that cuts a sound stopped early (seconds).
pub const CUT_FADE: f64 = 0.01;

/// One clip of a run as heard: when it starts, the volume each frame (time, volume), and when
/// it was cut (if before its end).
#[derive(Debug, Clone)]
pub struct Track {
    /// Global time of its first sample.
    pub start: f64,
    /// The samples.
    pub audio: Arc<Audio>,
    /// (time, volume) from the frames it played in, in time order.
    pub volume: Vec<(f64, f32)>,
    /// When it was stopped before its end, if it was.
    pub cut: Option<f64>,
}

impl Track {
    fn volume_at(&self, t: f64) -> f32 {
        let k = self.volume.partition_point(|v| v.0 <= t);
        match k {
            0 => self.volume.first().map_or(1.0, |v| v.1),
            k => self.volume[k - 1].1,
        }
    }

    /// The clip's sample at global time `t` (linear between samples; 0 outside it).
    fn sample(&self, t: f64) -> f32 {
        let x = (t - self.start) * f64::from(self.audio.rate);
        if x < 0.0 {
            return 0.0;
        }
        let i = x.floor() as usize;
        let s = &self.audio.samples;
        let (Some(&a), b) = (s.get(i), s.get(i + 1).copied()) else {
            return 0.0;
        };
        let f = (x - i as f64) as f32;
        f32::from(a) + (f32::from(b.unwrap_or(a)) - f32::from(a)) * f
    }

    fn gain(&self, t: f64) -> f32 {
        let fade = match self.cut {
            Some(c) if t >= c + CUT_FADE => return 0.0,
            Some(c) if t >= c => 1.0 - ((t - c) / CUT_FADE) as f32,
            _ => 1.0,
        };
        fade * self.volume_at(t)
    }
}

/// The mix of `tracks` from time 0 to `end` at `rate` samples a second.
pub fn mix(tracks: &[Track], rate: u32, end: f64) -> Vec<i16> {
    let n = (end.max(0.0) * f64::from(rate)).ceil() as usize;
    let mut out = vec![0.0f32; n];
    for tr in tracks {
        let from = ((tr.start * f64::from(rate)).floor().max(0.0)) as usize;
        let last = tr.cut.map_or(tr.start + tr.length(), |c| c + CUT_FADE);
        let to = ((last * f64::from(rate)).ceil() as usize).min(n);
        for (k, o) in out.iter_mut().enumerate().take(to).skip(from) {
            let t = k as f64 / f64::from(rate);
            *o += tr.sample(t) * tr.gain(t);
        }
    }
    out.into_iter()
        .map(|v| v.round().clamp(f32::from(i16::MIN), f32::from(i16::MAX)) as i16)
        .collect()
}

impl Track {
    /// The clip's own length (seconds).
    pub fn length(&self) -> f64 {
        self.audio.samples.len() as f64 / f64::from(self.audio.rate.max(1))
    }
}

/// `samples` as a mono 16-bit WAV file.
pub fn wav(samples: &[i16], rate: u32) -> Result<Vec<u8>, String> {
    let spec = hound::WavSpec {
        channels: 1,
        sample_rate: rate,
        bits_per_sample: 16,
        sample_format: hound::SampleFormat::Int,
    };
    let mut bytes = std::io::Cursor::new(Vec::new());
    let mut w = hound::WavWriter::new(&mut bytes, spec).map_err(|e| e.to_string())?;
    for &s in samples {
        w.write_sample(s).map_err(|e| e.to_string())?;
    }
    w.finalize().map_err(|e| e.to_string())?;
    Ok(bytes.into_inner())
}

/// Reads a WAV file as mono 16-bit audio (channels averaged; 8-, 24- and 32-bit and float
/// samples converted). The error names the file.
pub fn read_wav(path: &std::path::Path) -> Result<Audio, String> {
    let file = std::fs::File::open(path).map_err(|e| format!("{}: {e}", path.display()))?;
    read_wav_from(std::io::BufReader::new(file), &path.display().to_string())
}

/// Reads WAV data from `reader` as [`read_wav`] does; the error names `name`.
pub fn read_wav_from(reader: impl std::io::Read, name: &str) -> Result<Audio, String> {
    let mut r = hound::WavReader::new(reader).map_err(|e| format!("{name}: {e}"))?;
    let spec = r.spec();
    let channels = usize::from(spec.channels.max(1));
    let values: Vec<f32> = match spec.sample_format {
        hound::SampleFormat::Float => r
            .samples::<f32>()
            .filter_map(Result::ok)
            .map(|v| v * 32767.0)
            .collect(),
        hound::SampleFormat::Int => {
            let shift = i32::from(spec.bits_per_sample) - 16;
            (r.samples::<i32>().filter_map(Result::ok))
                .map(|v| {
                    if shift >= 0 {
                        (v >> shift) as f32
                    } else {
                        (v << -shift) as f32
                    }
                })
                .collect()
        }
    };
    let samples = values
        .chunks(channels)
        .map(|c| {
            (c.iter().sum::<f32>() / c.len() as f32)
                .round()
                .clamp(-32768.0, 32767.0) as i16
        })
        .collect();
    Ok(Audio {
        rate: spec.sample_rate,
        samples,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tone(rate: u32, seconds: f64) -> Arc<Audio> {
        let n = (seconds * f64::from(rate)) as usize;
        Arc::new(Audio {
            rate,
            samples: vec![10_000; n],
        })
    }

    #[test]
    fn clips_are_placed_at_their_pegs_at_their_volume_and_cut_with_a_fade() {
        let a = Track {
            start: 0.5,
            audio: tone(8000, 0.5),
            volume: vec![(0.0, 0.5)],
            cut: None,
        };
        let b = Track {
            start: 1.2,
            audio: tone(8000, 1.0),
            volume: vec![(0.0, 1.0)],
            cut: Some(1.5),
        };
        let out = mix(&[a, b], 8000, 2.0);
        assert_eq!(out.len(), 16_000);
        assert_eq!(out[3999], 0, "silent before the first clip");
        assert_eq!(out[4000], 5000, "the first clip at half volume from 0.5 s");
        assert_eq!(out[7999], 5000);
        assert_eq!(out[8000], 0, "it is 0.5 s long");
        assert_eq!(out[9600], 10_000, "the second at 1.2 s");
        assert!(
            out[12_040] > 0 && out[12_040] < 10_000,
            "fading after the cut at 1.5 s"
        );
        assert_eq!(out[12_080], 0, "gone 10 ms after the cut");
        let bytes = wav(&out, 8000).unwrap();
        let back = hound::WavReader::new(std::io::Cursor::new(bytes)).unwrap();
        assert_eq!(back.duration(), 16_000);
    }
}
