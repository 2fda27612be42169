//! The scenario-file form of a mechanism's element lists: `[[joints]]`,
//! `[[drives]]` and `[[forces]]` each take their own kinds, so an entry in
//! the wrong list is refused where it is, not silently accepted.
//!
//! Use with `#[serde(default, deserialize_with = "cdyn::planar::format::joints")]`
//! on a `Vec<Element<String>>`.

use super::element::{Element, Group};
use serde::Deserialize;
use serde::de::{self, DeserializeSeed, Deserializer, SeqAccess, Visitor};

/// A `[[joints]]` list: revolute, prismatic, distance, fixed_angle.
pub fn joints<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Vec<Element<String>>, D::Error> {
    Group::Joints.deserialize(deserializer)
}

/// A `[[drives]]` list: relative_angle, coordinate.
pub fn drives<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Vec<Element<String>>, D::Error> {
    Group::Drives.deserialize(deserializer)
}

/// A `[[forces]]` list: spring, torsion_spring, damper, rotary_damper, force, torque.
pub fn forces<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Vec<Element<String>>, D::Error> {
    Group::Forces.deserialize(deserializer)
}

/// A group reads its list entry by entry, so that an error is reported at
/// the entry (a path `joints[2]`) that caused it.
impl<'de> DeserializeSeed<'de> for Group {
    type Value = Vec<Element<String>>;

    fn deserialize<D: Deserializer<'de>>(self, deserializer: D) -> Result<Self::Value, D::Error> {
        deserializer.deserialize_seq(self)
    }
}

impl<'de> Visitor<'de> for Group {
    type Value = Vec<Element<String>>;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        write!(f, "a list of [[{}]] entries", self.name())
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
        let mut out = Vec::new();
        while let Some(element) = seq.next_element_seed(Entry(self))? {
            out.push(element);
        }
        Ok(out)
    }
}

/// One entry of a group's list: any element, refused unless of the group.
struct Entry(Group);

impl<'de> DeserializeSeed<'de> for Entry {
    type Value = Element<String>;

    fn deserialize<D: Deserializer<'de>>(self, deserializer: D) -> Result<Self::Value, D::Error> {
        let element = Element::<String>::deserialize(deserializer)?;
        if element.group() != self.0 {
            return Err(de::Error::custom(format!(
                "a {} belongs under [[{}]], not [[{}]]",
                element.kind(),
                element.group().name(),
                self.0.name()
            )));
        }
        Ok(element)
    }
}
