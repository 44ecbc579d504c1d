//! Design views for colour and material design (Tonn & Donath, "Color, material and light in
//! the design process"): the unfolded elevation of one building.

pub mod unfolded;
