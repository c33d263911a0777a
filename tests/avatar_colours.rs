//! The default avatar's clothes and hair are coloured by vertex along smooth lines: the border
//! between the shirt and the skin of the neck runs round the neck as a line, not as the
//! staircase of the mesh's faces.

use bml_realizer::character::avatar;
use glam::Vec3;

/// The body's places, colours and triangles (its first primitive).
fn body() -> (Vec<Vec3>, Vec<[f32; 3]>, Vec<[usize; 3]>) {
    let g = gltf::Gltf::from_slice(avatar::DEFAULT_GLB).unwrap();
    let blob = g.blob.as_deref().unwrap();
    let mesh = g.document.meshes().next().unwrap();
    let body = mesh.primitives().next().unwrap();
    assert_eq!(body.material().name(), Some("body"));
    let r = body.reader(|_| Some(blob));
    let places = r.read_positions().unwrap().map(Vec3::from).collect();
    let colours = r.read_colors(0).unwrap().into_rgb_f32().collect();
    let index: Vec<usize> = r
        .read_indices()
        .unwrap()
        .into_u32()
        .map(|i| i as usize)
        .collect();
    let tris = index.chunks(3).map(|t| [t[0], t[1], t[2]]).collect();
    (places, colours, tris)
}

#[test]
fn the_neckline_runs_round_the_neck_as_a_smooth_line() {
    let (places, colours, tris) = body();
    let model = avatar::default_model();
    let neck = (model.rest_world(model.node("vc7").unwrap()))
        .w_axis
        .truncate();
    // how much shirt a vertex is, by its red (skin 0.80, shirt 0.16)
    let shirt = |v: usize| ((0.80 - colours[v][0]) / (0.80 - 0.16)).clamp(0.0, 1.0);
    let near = |p: Vec3| {
        let r = ((p.x - neck.x).powi(2) + (p.z - neck.z).powi(2)).sqrt();
        r < 0.13 && (neck.y - 0.12..neck.y + 0.04).contains(&p.y)
    };
    // where each edge near the neck crosses half shirt, half skin
    const SECTORS: usize = 24;
    let mut crossings = vec![Vec::new(); SECTORS];
    for t in &tris {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let (sa, sb) = (shirt(a), shirt(b));
            if (sa - 0.5) * (sb - 0.5) >= 0.0 || !near(places[a]) || !near(places[b]) {
                continue;
            }
            let p = places[a].lerp(places[b], (0.5 - sa) / (sb - sa));
            let angle = (p.x - neck.x).atan2(p.z - neck.z) + std::f32::consts::PI;
            let s = ((angle / std::f32::consts::TAU * SECTORS as f32) as usize).min(SECTORS - 1);
            crossings[s].push(p.y);
        }
    }
    // a closed ring: the border crosses every sector round the neck
    let heights: Vec<f32> = (crossings.iter().enumerate())
        .map(|(s, c)| {
            assert!(!c.is_empty(), "no neckline in sector {s} of {SECTORS}");
            c.iter().sum::<f32>() / c.len() as f32
        })
        .collect();
    eprintln!("neckline heights round the neck: {heights:.3?}");
    // smooth: no sector's height stands out from its neighbours' mean by a centimetre
    for s in 0..SECTORS {
        let (before, after) = (
            heights[(s + SECTORS - 1) % SECTORS],
            heights[(s + 1) % SECTORS],
        );
        let kink = heights[s] - 0.5 * (before + after);
        assert!(
            kink.abs() < 0.01,
            "the neckline kinks by {kink:.3} m in sector {s}"
        );
    }
    // lower in front (the crew neck) than behind
    let (behind, front) = (heights[0], heights[SECTORS / 2]);
    assert!(
        front < behind - 0.02,
        "front {front:.3}, behind {behind:.3}"
    );
}
