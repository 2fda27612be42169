//! The built-in models by the names scenario files give them, and the one
//! place that builds each from its parameters. Adding a built-in model is a
//! file under `models/` plus a variant of [`Kind`] and its line in
//! [`Kind::example`]; a scenario reader that hands the parameters over needs
//! no change.

#[cfg(feature = "serde")]
use super::{
    Example, andrews, cartesian_pendulum, chain, damped_pendulum, double_pendulum, double_pendulum_angles, four_bar,
    four_bar_angles, moving_support_pendulum, slider_crank, theta_pendulum,
};

/// A built-in model, by the name scenario files give it (`kind = "chain"`,
/// snake_case). Each one's parameters are the fields of its parameter struct.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Deserialize, serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
#[non_exhaustive]
pub enum Kind {
    /// Example 1 of the paper in Cartesian coordinates: [`cartesian_pendulum`](super::cartesian_pendulum),
    /// [`PendulumParams`](super::PendulumParams).
    Pendulum,
    /// The same pendulum in its angle: [`theta_pendulum`](super::theta_pendulum),
    /// [`PendulumParams`](super::PendulumParams).
    PendulumTheta,
    /// A planar mechanism described body by body and joint by joint
    /// ([`Mechanism`](crate::planar::Mechanism)): not built from parameters,
    /// so `Kind::example` refuses it.
    Mechanism,
    /// A spatial mechanism described body by body and joint by joint
    /// ([`spatial::Mechanism`](crate::spatial::Mechanism)): not built from
    /// parameters either.
    Spatial,
    /// Andrews' squeezing mechanism at the test set's initial state:
    /// [`andrews`](super::andrews()), no parameters.
    Andrews,
    /// [`double_pendulum`](super::double_pendulum), [`DoublePendulumParams`](super::DoublePendulumParams).
    DoublePendulum,
    /// The same double pendulum in its two angles, its mass matrix `M(θ)`
    /// from the kinetic energy: [`double_pendulum_angles`](super::double_pendulum_angles),
    /// [`DoublePendulumParams`](super::DoublePendulumParams).
    DoublePendulumAngles,
    /// [`chain`](super::chain), [`ChainParams`](super::ChainParams).
    Chain,
    /// [`slider_crank`](super::slider_crank), [`SliderCrankParams`](super::SliderCrankParams).
    SliderCrank,
    /// [`four_bar`](super::four_bar), [`FourBarParams`](super::FourBarParams).
    FourBar,
    /// The same four-bar in its three joint angles, `M(q)` from the kinetic
    /// energy: [`four_bar_angles`](super::four_bar_angles), [`FourBarParams`](super::FourBarParams).
    FourBarAngles,
    /// [`moving_support_pendulum`](super::moving_support_pendulum),
    /// [`MovingSupportParams`](super::MovingSupportParams).
    MovingSupportPendulum,
    /// [`damped_pendulum`](super::damped_pendulum), [`DampedPendulumParams`](super::DampedPendulumParams).
    DampedPendulum,
}

impl Kind {
    /// Every kind, in declaration order.
    pub const ALL: [Kind; 13] = [
        Kind::Pendulum,
        Kind::PendulumTheta,
        Kind::Mechanism,
        Kind::Spatial,
        Kind::Andrews,
        Kind::DoublePendulum,
        Kind::DoublePendulumAngles,
        Kind::Chain,
        Kind::SliderCrank,
        Kind::FourBar,
        Kind::FourBarAngles,
        Kind::MovingSupportPendulum,
        Kind::DampedPendulum,
    ];

    /// Whether models of this kind are described body by body in the
    /// scenario (`[[bodies]]`, `[[joints]]`) rather than built from parameters.
    pub fn is_described(self) -> bool {
        matches!(self, Kind::Mechanism | Kind::Spatial)
    }

    /// The model of this kind, built from `parameters`: a map of the keys of
    /// its parameter struct, where unset keys keep the defaults and unknown
    /// keys are refused.
    ///
    /// The outer error is the deserializer's (an unknown key, a value of the
    /// wrong type: the caller knows where in its input that is); the inner
    /// one is the model's own validation (a value outside its domain).
    /// [`Kind::Mechanism`] has no parameters and is refused.
    #[cfg(feature = "serde")]
    pub fn example<'de, D: serde::Deserializer<'de>>(self, parameters: D) -> Result<crate::Result<Example>, D::Error> {
        use serde::de::Error as _;
        match self {
            Kind::Pendulum => build(parameters, cartesian_pendulum),
            Kind::PendulumTheta => build(parameters, theta_pendulum),
            Kind::Mechanism => Err(D::Error::custom(
                "a mechanism is built from its bodies, joints, drives and forces, not from parameters",
            )),
            Kind::Spatial => {
                Err(D::Error::custom("a spatial mechanism is built from its bodies and joints, not from parameters"))
            }
            Kind::Andrews => build(parameters, |NoParameters {}| andrews()),
            Kind::DoublePendulum => build(parameters, double_pendulum),
            Kind::DoublePendulumAngles => build(parameters, double_pendulum_angles),
            Kind::Chain => build(parameters, chain),
            Kind::SliderCrank => build(parameters, slider_crank),
            Kind::FourBar => build(parameters, four_bar),
            Kind::FourBarAngles => build(parameters, four_bar_angles),
            Kind::MovingSupportPendulum => build(parameters, moving_support_pendulum),
            Kind::DampedPendulum => build(parameters, damped_pendulum),
        }
    }
}

/// Reads the parameters `P` of a model, then builds it with `model`.
#[cfg(feature = "serde")]
fn build<'de, P: serde::Deserialize<'de>, D: serde::Deserializer<'de>>(
    parameters: D,
    model: impl FnOnce(P) -> crate::Result<Example>,
) -> Result<crate::Result<Example>, D::Error> {
    P::deserialize(parameters).map(model)
}

/// The parameters of a model that has none: an empty map, any key refused.
#[cfg(feature = "serde")]
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct NoParameters {}

#[cfg(all(test, feature = "serde"))]
mod tests {
    use super::*;
    use serde::de::value::{Error, MapDeserializer};

    fn no_parameters() -> MapDeserializer<'static, std::iter::Empty<(&'static str, f64)>, Error> {
        MapDeserializer::new(std::iter::empty())
    }

    #[test]
    fn every_kind_but_the_described_ones_builds_from_no_parameters() {
        for kind in Kind::ALL {
            let built = kind.example(no_parameters());
            if kind.is_described() {
                assert!(built.is_err());
            } else {
                let example = built.unwrap().unwrap_or_else(|e| panic!("{kind:?}: {e}"));
                assert_eq!(example.q0.len(), example.model.n(), "{kind:?}");
            }
        }
    }

    #[test]
    fn an_unknown_key_is_refused_by_name() {
        for kind in Kind::ALL {
            let map = MapDeserializer::<_, Error>::new([("no_such_key", 1.0)].into_iter());
            let e = kind.example(map).err().unwrap_or_else(|| panic!("{kind:?} accepted an unknown key"));
            if !kind.is_described() {
                assert!(e.to_string().contains("no_such_key"), "{kind:?}: {e}");
            }
        }
    }
}
