//! The models a deck can name. Each file holds the physics of one model and nothing else.
//!
//! Adding a model: write `models/<name>.rs` implementing [`crate::model::Model`] and add its
//! type to the list below. `cargo build` is the whole workflow.

pub mod concrete;
pub mod lps;
pub mod membrane;
pub mod micropolar;
pub mod pmb;
pub mod point;
pub mod thermal;

crate::model_registry! {
    pmb::Pmb,
    concrete::Concrete,
    lps::Lps,
    micropolar::Micropolar,
    thermal::Thermal,
    point::Point,
    membrane::Membrane,
}
