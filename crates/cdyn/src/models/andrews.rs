//! Andrews squeezing mechanism (in progress).

pub fn andrews() {}
