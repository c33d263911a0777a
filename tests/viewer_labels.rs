//! The names of world points never sit across a person in the viewer page (headless Chromium,
//! Debian's `chromium`; `#[ignore]`d here, `.ci/run` runs it with `--ignored`): the page says
//! where it put the people's boxes and the names on the screen (`data-placed` on the page's
//! root, once it is ready), and no name's box crosses a person's.

mod browser;
mod common;

use browser::{browse, page};
use serde_json::Value;

/// A box on the screen (normalized device coordinates).
fn edges(b: &Value) -> [f64; 4] {
    ["x0", "x1", "y0", "y1"].map(|k| b[k].as_f64().unwrap())
}

#[test]
#[ignore = "needs Debian's chromium; .ci/run installs it and runs this with --ignored"]
fn no_name_of_a_world_point_crosses_a_person() {
    // three people close together, the bluebox at the chest of the one who gestures
    let (_, dir) = page(
        "view-labels",
        &[
            "--no-idle",
            "--world",
            "fixtures/examples/world.json",
            "fixtures/examples/welcome.xml",
        ],
    );
    for t in ["0", "0.821", "2.5"] {
        let url = format!("file://{}#t={t}", dir.join("index.html").display());
        let (dom, console) = browse(&url, "--dump-dom");
        assert!(console.is_empty(), "at {t}: {console:?}");
        let start = dom
            .find("data-placed=\"")
            .expect("the page says where it put the names")
            + 13;
        let end = start + dom[start..].find('"').unwrap();
        let placed: Value = serde_json::from_str(&dom[start..end].replace("&quot;", "\"")).unwrap();
        let people: Vec<[f64; 4]> = placed["people"]
            .as_array()
            .unwrap()
            .iter()
            .map(edges)
            .collect();
        let names: Vec<[f64; 4]> = placed["names"]
            .as_array()
            .unwrap()
            .iter()
            .map(edges)
            .collect();
        assert_eq!((people.len(), names.len()), (3, 6), "at {t}");
        for n in &names {
            for p in &people {
                let crosses = n[1] > p[0] && n[0] < p[1] && n[3] > p[2] && n[2] < p[3];
                assert!(
                    !crosses,
                    "at {t}: a name at {n:?} crosses a person at {p:?}"
                );
            }
            // and stays in the view
            assert!(
                n[0] > -1.0 && n[1] < 1.0,
                "at {t}: a name at {n:?} leaves the view"
            );
        }
    }
}
