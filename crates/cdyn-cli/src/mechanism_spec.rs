//! Mechanisms in scenario files: `[[bodies]]`, `[[joints]]`, `[[drives]]`
//! and `[[forces]]`, turned into a [`Mechanism`]. Every mistake names the
//! entry (`joints[2] (revolute)`) and the key.

use anyhow::{Result, anyhow, bail};
use cdyn::planar::{Body, BodyId, Coordinate, Element, Mechanism};
use cdyn::timefn::TimeFn;
use serde::Deserialize;

#[derive(Debug, Deserialize, Clone)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    pub name: String,
    pub mass: f64,
    /// Omit for a point mass.
    pub inertia: Option<f64>,
    pub position: [f64; 2],
    #[serde(default)]
    pub angle: f64,
    #[serde(default)]
    pub velocity: [f64; 2],
    #[serde(default)]
    pub angular_velocity: f64,
}

/// A joint, drive or force entry: one flat table whose keys depend on `kind`.
#[derive(Debug, Deserialize, Clone)]
#[serde(deny_unknown_fields)]
pub struct ElementSpec {
    pub kind: String,
    pub a: Option<String>,
    pub b: Option<String>,
    pub body: Option<String>,
    pub point_a: Option<[f64; 2]>,
    pub point_b: Option<[f64; 2]>,
    pub point: Option<[f64; 2]>,
    pub axis: Option<[f64; 2]>,
    pub length: Option<f64>,
    pub angle: Option<f64>,
    pub coordinate: Option<String>,
    pub function: Option<FunctionSpec>,
    pub stiffness: Option<f64>,
    pub rest_length: Option<f64>,
    pub rest_angle: Option<f64>,
    pub damping: Option<f64>,
    pub fx: Option<FunctionSpec>,
    pub fy: Option<FunctionSpec>,
    pub torque: Option<FunctionSpec>,
}

/// A function of time: a number, or `{ polynomial = [c0, c1, …], sine = [[amplitude, ω, phase], …] }`.
#[derive(Debug, Deserialize, Clone)]
#[serde(untagged)]
pub enum FunctionSpec {
    Constant(f64),
    Terms {
        #[serde(default)]
        polynomial: Vec<f64>,
        #[serde(default)]
        sine: Vec<[f64; 3]>,
    },
}

impl FunctionSpec {
    pub fn time_fn(&self) -> TimeFn {
        match self {
            FunctionSpec::Constant(c) => TimeFn::constant(*c),
            FunctionSpec::Terms { polynomial, sine } => TimeFn { polynomial: polynomial.clone(), sines: sine.clone() },
        }
    }
}

/// Which keys each kind uses: required first, then optional.
fn keys(group: &str, kind: &str) -> Option<(&'static [&'static str], &'static [&'static str])> {
    Some(match (group, kind) {
        ("joints", "revolute") => (&["a", "b"], &["point_a", "point_b"]),
        ("joints", "prismatic") => (&["a", "b", "axis"], &["point_a", "point_b"]),
        ("joints", "distance") => (&["a", "b", "length"], &["point_a", "point_b"]),
        ("joints", "fixed_angle") => (&["a", "b"], &["angle"]),
        ("drives", "relative_angle") => (&["a", "b", "function"], &[]),
        ("drives", "coordinate") => (&["body", "coordinate", "function"], &[]),
        ("forces", "spring") => (&["a", "b", "stiffness"], &["point_a", "point_b", "rest_length"]),
        ("forces", "torsion_spring") => (&["a", "b", "stiffness"], &["rest_angle"]),
        ("forces", "damper") => (&["a", "b", "damping"], &["point_a", "point_b"]),
        ("forces", "rotary_damper") => (&["a", "b", "damping"], &[]),
        ("forces", "force") => (&["body"], &["point", "fx", "fy"]),
        ("forces", "torque") => (&["body", "torque"], &[]),
        _ => return None,
    })
}

fn kinds(group: &str) -> &'static str {
    match group {
        "joints" => "revolute, prismatic, distance, fixed_angle",
        "drives" => "relative_angle, coordinate",
        _ => "spring, torsion_spring, damper, rotary_damper, force, torque",
    }
}

impl ElementSpec {
    /// The keys this entry sets.
    fn present(&self) -> Vec<&'static str> {
        let mut out = Vec::new();
        let mut has = |k: &'static str, set: bool| {
            if set {
                out.push(k)
            }
        };
        has("a", self.a.is_some());
        has("b", self.b.is_some());
        has("body", self.body.is_some());
        has("point_a", self.point_a.is_some());
        has("point_b", self.point_b.is_some());
        has("point", self.point.is_some());
        has("axis", self.axis.is_some());
        has("length", self.length.is_some());
        has("angle", self.angle.is_some());
        has("coordinate", self.coordinate.is_some());
        has("function", self.function.is_some());
        has("stiffness", self.stiffness.is_some());
        has("rest_length", self.rest_length.is_some());
        has("rest_angle", self.rest_angle.is_some());
        has("damping", self.damping.is_some());
        has("fx", self.fx.is_some());
        has("fy", self.fy.is_some());
        has("torque", self.torque.is_some());
        out
    }
}

/// The scenario's mechanism tables.
pub struct MechanismSpec<'a> {
    pub gravity: [f64; 2],
    pub bodies: &'a [BodySpec],
    pub joints: &'a [ElementSpec],
    pub drives: &'a [ElementSpec],
    pub forces: &'a [ElementSpec],
}

impl MechanismSpec<'_> {
    /// The mechanism, and for every element the entry that made it (`joints[2] (revolute)`).
    pub fn build(&self, file: &str) -> Result<(Mechanism, Vec<String>)> {
        let mut m = Mechanism::new(self.gravity);
        if self.bodies.is_empty() {
            bail!("{file}: a mechanism needs at least one [[bodies]] entry");
        }
        for (i, b) in self.bodies.iter().enumerate() {
            let at = format!("{file}: bodies[{i}] ({})", b.name);
            if b.name.is_empty() || b.name == "ground" {
                bail!("{file}: bodies[{i}]: name {:?} is reserved or empty", b.name);
            }
            if self.bodies[..i].iter().any(|o| o.name == b.name) {
                bail!("{at}: a body with this name already exists");
            }
            if !(b.mass.is_finite() && b.mass > 0.0) {
                bail!("{at}: mass = {} must be finite and positive", b.mass);
            }
            if let Some(inertia) = b.inertia.filter(|i| !(i.is_finite() && *i > 0.0)) {
                bail!("{at}: inertia = {inertia} must be finite and positive (omit it for a point mass)");
            }
            let state = b.position.iter().chain(&b.velocity).chain([&b.angle, &b.angular_velocity]);
            if let Some(x) = state.into_iter().find(|x| !x.is_finite()) {
                bail!("{at}: initial state contains {x}");
            }
            if b.inertia.is_none() && (b.angle != 0.0 || b.angular_velocity != 0.0) {
                bail!("{at}: a point mass (no inertia) has no angle or angular_velocity");
            }
            m.push(Body {
                name: b.name.clone(),
                mass: b.mass,
                inertia: b.inertia,
                position: b.position,
                angle: b.angle,
                velocity: b.velocity,
                angular_velocity: b.angular_velocity,
            });
        }
        let mut entries = Vec::new();
        for (group, list) in [("joints", self.joints), ("drives", self.drives), ("forces", self.forces)] {
            for (i, e) in list.iter().enumerate() {
                let at = format!("{group}[{i}] ({})", e.kind);
                let element = self.element(group, e).map_err(|why| anyhow!("{file}: {at}: {why}"))?;
                m.add(element);
                entries.push(at);
            }
        }
        Ok((m, entries))
    }

    fn body(&self, key: &str, name: &Option<String>) -> Result<BodyId> {
        let name = name.as_deref().ok_or_else(|| anyhow!("missing `{key}`"))?;
        if name == "ground" {
            return Ok(BodyId::Ground);
        }
        self.bodies
            .iter()
            .position(|b| b.name == name)
            .map(BodyId::Body)
            .ok_or_else(|| anyhow!("{key} = {name:?}: no body of that name (and not \"ground\")"))
    }

    fn element(&self, group: &str, e: &ElementSpec) -> Result<Element> {
        let (required, optional) = keys(group, &e.kind)
            .ok_or_else(|| anyhow!("unknown kind {:?}; expected one of {}", e.kind, kinds(group)))?;
        for k in e.present() {
            if !required.contains(&k) && !optional.contains(&k) {
                bail!("key `{k}` is not used by a {}", e.kind);
            }
        }
        if let Some(k) = required.iter().find(|k| !e.present().contains(k)) {
            bail!("missing `{k}`");
        }
        let number = |key: &str, x: Option<f64>| -> Result<f64> {
            let x = x.unwrap_or(0.0);
            if x.is_finite() { Ok(x) } else { bail!("{key} = {x} must be finite") }
        };
        let (pa, pb) = (e.point_a.unwrap_or([0.0; 2]), e.point_b.unwrap_or([0.0; 2]));
        let f = |x: &Option<FunctionSpec>| x.as_ref().map_or(TimeFn::constant(0.0), FunctionSpec::time_fn);
        let ab = || -> Result<(BodyId, BodyId)> { Ok((self.body("a", &e.a)?, self.body("b", &e.b)?)) };
        Ok(match (group, e.kind.as_str()) {
            ("joints", "revolute") => {
                let (a, b) = ab()?;
                Element::Revolute { a, pa, b, pb }
            }
            ("joints", "prismatic") => {
                let (a, b) = ab()?;
                Element::Prismatic { a, pa, b, pb, axis: e.axis.unwrap_or_default() }
            }
            ("joints", "distance") => {
                let (a, b) = ab()?;
                Element::Distance { a, pa, b, pb, length: number("length", e.length)? }
            }
            ("joints", "fixed_angle") => {
                let (a, b) = ab()?;
                Element::FixedAngle { a, b, angle: number("angle", e.angle)? }
            }
            ("drives", "relative_angle") => {
                let (a, b) = ab()?;
                Element::DriveAngle { a, b, f: f(&e.function) }
            }
            ("drives", "coordinate") => {
                let coordinate = match e.coordinate.as_deref() {
                    Some("x") => Coordinate::X,
                    Some("y") => Coordinate::Y,
                    Some("angle") => Coordinate::Angle,
                    other => bail!("coordinate = {other:?}: expected \"x\", \"y\" or \"angle\""),
                };
                Element::DriveCoordinate { body: self.body("body", &e.body)?, coordinate, f: f(&e.function) }
            }
            ("forces", "spring") => {
                let (a, b) = ab()?;
                let (stiffness, rest_length) =
                    (number("stiffness", e.stiffness)?, number("rest_length", e.rest_length)?);
                Element::Spring { a, pa, b, pb, stiffness, rest_length }
            }
            ("forces", "torsion_spring") => {
                let (a, b) = ab()?;
                Element::TorsionSpring {
                    a,
                    b,
                    stiffness: number("stiffness", e.stiffness)?,
                    rest_angle: number("rest_angle", e.rest_angle)?,
                }
            }
            ("forces", "damper") => {
                let (a, b) = ab()?;
                Element::Damper { a, pa, b, pb, damping: number("damping", e.damping)? }
            }
            ("forces", "rotary_damper") => {
                let (a, b) = ab()?;
                Element::RotaryDamper { a, b, damping: number("damping", e.damping)? }
            }
            ("forces", "force") => Element::AppliedForce {
                body: self.body("body", &e.body)?,
                point: e.point.unwrap_or([0.0; 2]),
                fx: f(&e.fx),
                fy: f(&e.fy),
            },
            ("forces", "torque") => Element::AppliedTorque { body: self.body("body", &e.body)?, f: f(&e.torque) },
            _ => unreachable!("keys() accepted the kind"),
        })
    }
}
