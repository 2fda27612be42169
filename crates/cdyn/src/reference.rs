// TEMPORARY placeholder until the elliptic reference lands.
#[derive(Clone, Debug)]
pub struct PendulumExact;
#[derive(Clone, Debug, PartialEq)]
pub enum ReferenceError {
    Separatrix,
}
impl PendulumExact {
    pub fn new(_w2: f64, _theta0: f64, _omega0: f64) -> Result<Self, ReferenceError> {
        Err(ReferenceError::Separatrix)
    }
    pub fn angle(&self, _t: f64) -> (f64, f64) {
        (0.0, 0.0)
    }
}
