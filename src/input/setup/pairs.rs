//! The deck's pair law, built for the bonded model `M`: the one place where `[pair] law`
//! becomes a type, after which the non-bonded pass is monomorphized for it.

use crate::engine::pair_pass::{NonBonded, PairPass};
use crate::input::deck::{DeckError, Scene};
use crate::model::pair::{PairBuild, PairLaw, PairVisitor};
use crate::model::Model;
use std::marker::PhantomData;

/// The non-bonded pass of `scene` with an empty neighbour list, if the deck has a `[pair]`.
pub(super) fn pair_pass<M: Model>(
    model: &M,
    scene: &Scene,
) -> Result<Option<Box<dyn NonBonded<M>>>, DeckError> {
    let Some(spec) = &scene.pair else {
        return Ok(None);
    };
    let bulk: Vec<f64> = (0..scene.materials.len())
        .map(|m| {
            let (lambda, mu) = model.lame(m as u16);
            lambda + 2.0 * mu / 3.0
        })
        .collect();
    let build = PairBuild {
        own: &spec.own,
        between: &spec.between,
        mixing: spec.mixing,
        cutoff: spec.cutoff,
        shift: spec.shift,
        horizon: scene.horizon,
        spacing: scene.spacing,
        bulk_modulus: &bulk,
    };
    let make = Make::<M> {
        skin: spec.skin,
        exclude_bonded: spec.exclude_bonded,
        model: PhantomData,
    };
    crate::pairs::visit(&spec.law, &build, make)
        .map_err(|e| scene.pair_error(&e))
        .map(Some)
}

struct Make<M> {
    skin: Option<f64>,
    exclude_bonded: bool,
    model: PhantomData<M>,
}

impl<M: Model> PairVisitor for Make<M> {
    type Output = Box<dyn NonBonded<M>>;

    fn visit<L: PairLaw>(self, law: L) -> Self::Output {
        // LAMMPS's LJ default is 0.3σ against a 2.5σ cutoff; 0.3 of the cutoff keeps rebuilds
        // rare for any law at the price of a few more listed pairs.
        let skin = self.skin.unwrap_or(0.3 * law.cutoff());
        Box::new(PairPass::new(law, skin, self.exclude_bonded))
    }
}
