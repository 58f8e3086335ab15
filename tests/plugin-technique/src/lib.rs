//! wip
pub fn link() {}
