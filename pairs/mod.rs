//! The non-bonded pair laws a deck can name in `[pair] law`. Each file holds the physics of one
//! law and nothing else; the engine's pair pass (`src/engine/pair_pass.rs`) finds the pairs.
//!
//! Adding a law: write `pairs/<name>.rs` implementing [`crate::model::pair::PairLaw`] and add
//! its type to the list below.

pub mod contact;
pub mod lj;
pub mod morse;
pub mod wca;

crate::pair_registry! {
    lj::LennardJones,
    wca::Wca,
    morse::Morse,
    contact::Contact,
}
