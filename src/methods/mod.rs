//! Indirect-light methods, one module each (ALGORITHM.md sections 4 and 5).
//! Each writes the full-resolution indirect irradiance image.

pub mod gather;
pub mod hisr;
pub mod isr;
