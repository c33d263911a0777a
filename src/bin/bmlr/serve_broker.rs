//! What `bmlr serve --mqtt URL` and `--stomp URL` need, checked from the command line: the
//! link (connected), the topics of presence and of the shared world, the dialect (this
//! project's topics, ipaaca, or AsapRealizer's or Greta's ActiveMQ conventions) and the frames
//! file. A bad flag is an error naming it; a broker that cannot be reached, one naming its URL.

use std::time::Duration;

use bml_realizer::ports::broker::ipaaca::iu::Requests;
use bml_realizer::ports::broker::{
    level_ok, BrokerUrl, Cells, Ipaaca, Link, LinkOptions, StompLink, StompOptions, StompUrl,
    Topics, Wire, CELL_SIZE,
};
use bml_realizer::realizer::Realizer;

use crate::brokered::Brokered;
use crate::dialect::Dialect;
use crate::serve::{Flavour, ServeArgs};

/// AsapRealizer's ActiveMQ topics (its `AMQBMLConstants`): blocks in, feedback out.
pub const ASAP_TOPICS: (&str, &str) = ("asap.bml.request", "asap.bml.feedback");

/// Greta's ActiveMQ topics (its `BMLReceiver` and `BMLCallbacksSender` defaults).
pub const GRETA_TOPICS: (&str, &str) = ("greta.BML", "greta.output.feedback.BML");

/// Checks the broker flags and connects.
pub fn brokered(args: &ServeArgs, realizer: &Realizer) -> Result<Brokered, String> {
    let stomp = args.stomp.is_some();
    let prefix = args.prefix.as_deref().unwrap_or("bml");
    let topics = match stomp {
        true => Topics::dotted(prefix),
        false => Topics::new(prefix),
    }
    .map_err(|e| format!("--prefix {e}"))?;
    let name = (args.name.clone()).unwrap_or_else(|| format!("bmlr-{}", std::process::id()));
    if !level_ok(&name) {
        return Err(format!(
            "--name '{name}' is not a topic level (no '/', '+', '#')"
        ));
    }
    if let Some(bad) = args.characters.iter().find(|c| !level_ok(c)) {
        return Err(format!(
            "--characters '{bad}' is not a topic level (no '/', '+', '#')"
        ));
    }
    let until = args.until.unwrap_or(f64::INFINITY);
    if until.is_nan() || until < 0.0 {
        return Err("--until must be a number of seconds".into());
    }
    let pair = |(i, o): (&str, &str)| match args.topics.as_slice() {
        [] => Ok((i.to_string(), o.to_string())),
        [i, o] if level_ok(i) && level_ok(o) => Ok((i.clone(), o.clone())),
        _ => Err("--topics takes two topics, IN,OUT (no '/', '+', '#')".to_string()),
    };
    let dialect = match (&args.mqtt, args.flavour) {
        (Some(_), _) if !args.ipaaca.is_empty() => Dialect::Ipaaca(
            Ipaaca::new(&args.ipaaca, &name).map_err(|e| format!("--ipaaca {e}"))?,
            Requests::default(),
        ),
        (Some(_), _) => Dialect::Topics(topics.clone()),
        (None, Some(Flavour::Greta)) => {
            let (i, o) = pair(GRETA_TOPICS)?;
            Dialect::Greta(i, o)
        }
        (None, _) => {
            let (i, o) = pair(ASAP_TOPICS)?;
            Dialect::Asap(i, o)
        }
    };
    // (the world's cells are listened to as the characters walk)
    let subscriptions = dialect.subscriptions(&topics, &args.characters);
    let cells = Cells::new(args.cell.unwrap_or(CELL_SIZE)).map_err(|e| format!("--cell {e}"))?;
    let frames = crate::serve::live_frames(args, realizer).map_err(|e| format!("--frames {e}"))?;
    let (wire, url): (Box<dyn Wire>, String) = match (&args.mqtt, &args.stomp) {
        (Some(url), _) => {
            let url = BrokerUrl::parse(url).map_err(|e| format!("--mqtt {e}"))?;
            let link = Link::connect(LinkOptions {
                url: url.clone(),
                client_id: name.clone(),
                subscriptions,
                presence: Some(topics.presence(&name)),
                inbox: 4_096,
                start_tries: 6,
            })
            .map_err(|e| format!("--mqtt {e}"))?;
            (Box::new(link), url.to_string())
        }
        (None, Some(url)) => {
            let url = StompUrl::parse(url).map_err(|e| format!("--stomp {e}"))?;
            let link = StompLink::connect(StompOptions {
                url: url.clone(),
                subscriptions: subscriptions
                    .iter()
                    .map(|s| format!("/topic/{s}"))
                    .collect(),
                presence: Some(format!("/topic/{}", topics.presence(&name))),
                inbox: 4_096,
                start_tries: 6,
            })
            .map_err(|e| format!("--stomp {e}"))?;
            (Box::new(link), url.to_string())
        }
        (None, None) => return Err("give --mqtt or --stomp".into()),
    };
    Ok(Brokered {
        wire,
        url,
        topics,
        cells,
        stomp,
        dialect,
        characters: args.characters.iter().cloned().collect(),
        format: args.format.unwrap_or(crate::setup::FormatArg::Xml).into(),
        period: Duration::from_secs_f64(1.0 / args.fps),
        queue_limit: args.queue_limit.unwrap_or(crate::brokered::QUEUE_LIMIT),
        until,
        frames,
    })
}
