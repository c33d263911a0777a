//! Characters that another realizer moves — over a broker, realizers that share one world each
//! publish where their characters stand and place the others' here. Such a character is placed
//! in this realizer's world (walkers here see it in the crowd, gaze and pointing can aim at it),
//! but it is never made a character of this realizer when a walker asks it for room (the host
//! sends its blocks to the realizer that moves it). A walker there that asks one of this
//! realizer's characters for room ([`remote_asks`](Realizer::remote_asks)) is heard as a walker
//! here would be: the one asked steps aside.

use super::Realizer;
use crate::world::Placement;

impl Realizer {
    /// Places character `id`, which another realizer moves, at `at` (world frame). Refused for
    /// a character this realizer has (it moves that one itself) and for a place that is not
    /// finite.
    pub fn place_remote(&mut self, id: &str, at: Placement) -> Result<(), String> {
        if self.characters.contains_key(id) {
            return Err(format!(
                "character '{id}' is one of this realizer's: another cannot move it"
            ));
        }
        self.world_mut().place(id, at)?;
        self.remote.insert(id.to_string());
        Ok(())
    }

    /// Notes whom character `id`, moved by another realizer, asks to make room (`None`: nobody).
    /// Refused for a character that is not remote.
    pub fn remote_asks(&mut self, id: &str, asked: Option<&str>) -> Result<(), String> {
        if !self.remote.contains(id) {
            return Err(format!("character '{id}' is not moved by another realizer"));
        }
        match asked {
            Some(a) => self.remote_asks.insert(id.to_string(), a.to_string()),
            None => self.remote_asks.remove(id),
        };
        Ok(())
    }

    /// Whom this realizer's character `id` asks to make room now, if anyone (for other
    /// realizers: the character asked may be theirs).
    pub fn asks(&self, id: &str) -> Option<&str> {
        let crowd = self.world.crowd();
        let asked = crowd.asked_by(crowd.index(id)?)?;
        Some(crowd.id(asked))
    }

    /// Takes character `id`, which another realizer moves (or which the world file placed
    /// for another realizer), out of this realizer's world: nothing has been heard of it for a
    /// while. Refused for a character this realizer has.
    pub fn forget_remote(&mut self, id: &str) -> Result<(), String> {
        if self.characters.contains_key(id) {
            return Err(format!(
                "character '{id}' is one of this realizer's: it stays in the world"
            ));
        }
        self.world_mut().unplace(id);
        self.remote.remove(id);
        self.remote_asks.remove(id);
        Ok(())
    }

    /// Whether character `id` is moved by another realizer ([`place_remote`](Self::place_remote)).
    pub fn is_remote(&self, id: &str) -> bool {
        self.remote.contains(id)
    }
}
