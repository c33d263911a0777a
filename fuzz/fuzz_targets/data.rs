//! Fuzz target for the data files a user hands the realizer: a world file, a compound
//! controllers file and a nets file. No input may panic the readers; a world that loads must
//! give every point the same place seen from each placed character and back, a compound file
//! that loads must only hold definitions that validate, and nets that load must step.
#![no_main]

use bml_realizer::character::dynamics::compound::CompoundLibrary;
use bml_realizer::world::World;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok((world, _)) = World::from_json(text) {
        for (id, at) in world.placements() {
            let seen = world.seen_from(id);
            for (name, p) in world.points() {
                let back = at.to_world(seen.get(name).expect("every point is seen"));
                let tolerance = 1e-3 * (1.0 + p.length() + at.position.length());
                assert!(
                    back.distance(p) <= tolerance || !back.is_finite(),
                    "{name}: {p} vs {back}"
                );
            }
        }
    }
    if let Ok(nets) = bml_realizer::world::nets::file::read(text, &Default::default()) {
        let mut nets = bml_realizer::world::nets::Nets::new(nets, Default::default());
        struct Nothing;
        impl bml_realizer::world::nets::Senses for Nothing {
            fn sees(&self, _: &str, _: &str) -> bool {
                false
            }
            fn distance(&self, _: &str, _: &str) -> Option<f32> {
                None
            }
            fn reached(&self, _: Option<&str>, _: &str) -> bool {
                false
            }
        }
        for k in 0..3 {
            nets.step(f64::from(k), &Nothing);
        }
    }
    if let Ok(library) = CompoundLibrary::from_json(text) {
        for spec in library.specs() {
            spec.validate().expect("a loaded compound validates");
        }
    }
});
