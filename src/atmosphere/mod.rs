//! Atmosphere (work in progress in this commit).
