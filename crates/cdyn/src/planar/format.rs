//! The scenario-file form of a mechanism's element lists: `[[joints]]`,
//! `[[drives]]` and `[[forces]]` each take their own kinds, so an entry in
//! the wrong list is refused where it is, not silently accepted.
//!
//! Use with `#[serde(default, deserialize_with = "cdyn::planar::format::joints")]`
//! on a `Vec<Element<String>>`.

use super::element::{Element, Group};
use serde::Deserialize;
use serde::de::{self, DeserializeSeed, Deserializer, SeqAccess, Visitor};

/// A `[[joints]]` list: revolute, prismatic, distance, fixed_angle, knife_edge.
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::timefn::TimeFn;
    use crate::planar::{BodyId, Coordinate, Mechanism};

    const CRANK: BodyId = BodyId::Body(0);
    const BOB: BodyId = BodyId::Body(1);
    const GROUND: BodyId = BodyId::Ground;

    /// A rigid crank and a point-mass bob, under gravity.
    fn bodies() -> Mechanism {
        let mut m = Mechanism::new([0.0, -9.81]);
        m.rigid("crank", 1.0, 0.1, [0.5, 0.0], 0.2);
        m.point("bob", 2.0, [1.0, -1.0]);
        m
    }

    /// Every kind in its file form, with the element it describes.
    fn every_kind() -> Vec<(&'static str, Element)> {
        let f = |c: f64| TimeFn::constant(c);
        vec![
            (
                "kind = 'revolute'\na = 'ground'\nb = 'crank'\npoint_b = [-0.5, 0.0]",
                Element::Revolute { a: GROUND, pa: [0.0, 0.0], b: CRANK, pb: [-0.5, 0.0], limit: None },
            ),
            (
                "kind = 'prismatic'\na = 'ground'\nb = 'bob'\naxis = [1.0, 0.5]",
                Element::Prismatic { a: GROUND, pa: [0.0, 0.0], b: BOB, pb: [0.0, 0.0], axis: [1.0, 0.5], limit: None },
            ),
            (
                "kind = 'distance'\na = 'crank'\npoint_a = [0.5, 0.0]\nb = 'bob'\nlength = 1.2",
                Element::Distance { a: CRANK, pa: [0.5, 0.0], b: BOB, pb: [0.0, 0.0], length: 1.2 },
            ),
            (
                "kind = 'fixed_angle'\na = 'ground'\nb = 'crank'",
                Element::FixedAngle { a: GROUND, b: CRANK, angle: 0.0 },
            ),
            (
                "kind = 'knife_edge'\nbody = 'crank'\npoint = [0.5, 0.0]\nblade = [1.0, 0.2]",
                Element::KnifeEdge { body: CRANK, point: [0.5, 0.0], blade: [1.0, 0.2] },
            ),
            (
                "kind = 'coordinate'\nbody = 'bob'\ncoordinate = 'y'\nfunction = { sine = [[0.1, 2.0, 0.3]] }",
                Element::DriveCoordinate { body: BOB, coordinate: Coordinate::Y, f: TimeFn::sine(0.1, 2.0, 0.3) },
            ),
            (
                "kind = 'relative_angle'\na = 'ground'\nb = 'crank'\nfunction = { polynomial = [0.2, 6.0] }",
                Element::DriveAngle { a: GROUND, b: CRANK, f: TimeFn::linear(0.2, 6.0) },
            ),
            (
                "kind = 'spring'\na = 'crank'\npoint_a = [0.5, 0.0]\nb = 'ground'\npoint_b = [0.0, 1.0]\nstiffness = 100.0",
                Element::Spring {
                    a: CRANK,
                    pa: [0.5, 0.0],
                    b: GROUND,
                    pb: [0.0, 1.0],
                    stiffness: 100.0,
                    rest_length: 0.0,
                },
            ),
            (
                "kind = 'torsion_spring'\na = 'ground'\nb = 'crank'\nstiffness = 2.0\nrest_angle = 0.1",
                Element::TorsionSpring { a: GROUND, b: CRANK, stiffness: 2.0, rest_angle: 0.1 },
            ),
            (
                "kind = 'damper'\na = 'bob'\nb = 'ground'\npoint_b = [2.0, 0.0]\ndamping = 5.0",
                Element::Damper { a: BOB, pa: [0.0, 0.0], b: GROUND, pb: [2.0, 0.0], damping: 5.0 },
            ),
            (
                "kind = 'rotary_damper'\na = 'ground'\nb = 'crank'\ndamping = 0.3",
                Element::RotaryDamper { a: GROUND, b: CRANK, damping: 0.3 },
            ),
            (
                "kind = 'force'\nbody = 'crank'\npoint = [0.5, 0.0]\nfy = -2.0",
                Element::AppliedForce { body: CRANK, point: [0.5, 0.0], fx: TimeFn::default(), fy: f(-2.0) },
            ),
            ("kind = 'torque'\nbody = 'crank'\ntorque = 0.5", Element::AppliedTorque { body: CRANK, f: f(0.5) }),
        ]
    }

    #[test]
    fn every_kind_reads_from_its_file_form_and_builds_the_hand_made_model() {
        let (q, v, t) = ([0.45, 0.1, 0.3, 1.1, -0.9], [0.2, -0.1, 0.7, -0.3, 0.4], 0.3);
        for (text, hand) in every_kind() {
            let read: Element<String> = toml::from_str(text).unwrap_or_else(|e| panic!("{text}: {e}"));
            assert!(text.starts_with(&format!("kind = '{}'", read.kind())), "{text}");
            let (mut from_file, mut by_hand) = (bodies(), bodies());
            from_file.add_named(read).unwrap();
            by_hand.add(hand);
            assert_eq!(from_file.elements, by_hand.elements, "{text}");
            let (a, b) = (from_file.build().unwrap().model, by_hand.build().unwrap().model);
            assert_eq!((a.n(), a.m()), (b.n(), b.m()), "{text}");
            let (mut phi_a, mut phi_b) = (vec![0.0; a.m()], vec![0.0; b.m()]);
            a.constraint_values(&q, t, &mut phi_a);
            b.constraint_values(&q, t, &mut phi_b);
            assert_eq!(phi_a, phi_b, "{text}");
            let (mut grad_a, mut grad_b) = (vec![0.0; 5], vec![0.0; 5]);
            assert_eq!(a.potential(&q, Some(&mut grad_a)), b.potential(&q, Some(&mut grad_b)), "{text}");
            assert_eq!(grad_a, grad_b, "{text}");
            let (mut f_a, mut f_b) = (vec![0.0; 5], vec![0.0; 5]);
            assert_eq!(a.add_forces(&q, &v, t, &mut f_a), b.add_forces(&q, &v, t, &mut f_b), "{text}");
            assert_eq!(f_a, f_b, "{text}");
        }
    }

    #[derive(serde::Deserialize)]
    struct Lists {
        #[serde(default, deserialize_with = "joints")]
        joints: Vec<Element<String>>,
        #[serde(default, deserialize_with = "drives")]
        drives: Vec<Element<String>>,
        #[serde(default, deserialize_with = "forces")]
        forces: Vec<Element<String>>,
    }

    #[test]
    fn each_list_takes_its_own_kinds() {
        let mut lists = Lists { joints: vec![], drives: vec![], forces: vec![] };
        for (text, _) in every_kind() {
            let read: Element<String> = toml::from_str(text).unwrap();
            for group in [Group::Joints, Group::Drives, Group::Forces] {
                let file = format!("[[{}]]\n{text}", group.name());
                match toml::from_str::<Lists>(&file) {
                    Ok(one) if group == read.group() => {
                        lists.joints.extend(one.joints);
                        lists.drives.extend(one.drives);
                        lists.forces.extend(one.forces);
                    }
                    Ok(_) => panic!("{file}: accepted under the wrong list"),
                    Err(e) if group == read.group() => panic!("{file}: {e}"),
                    Err(e) => assert!(e.to_string().contains(&format!("[[{}]]", read.group().name())), "{e}"),
                }
            }
        }
        assert_eq!((lists.joints.len(), lists.drives.len(), lists.forces.len()), (5, 2, 6));
    }

    #[test]
    fn unknown_names_and_keys_are_refused() {
        let mut m = bodies();
        let read: Element<String> = toml::from_str("kind = 'revolute'\na = 'ground'\nb = 'crunk'").unwrap();
        let err = m.add_named(read).err().unwrap().to_string();
        assert!(err.contains("element 0 (revolute)") && err.contains("b = \"crunk\""), "{err}");
        let err = toml::from_str::<Element<String>>("kind = 'revolute'\na = 'ground'\nb = 'crank'\nlength = 1.0");
        assert!(err.unwrap_err().to_string().contains("length"));
    }
}
