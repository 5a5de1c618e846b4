//! A model: a ball, gravity and a list of effects.

use crate::effects::{Coulomb, Effect, LinearDamping, LinearSpring};
use crate::{Ball, ModelError};

/// Standard gravity, m/s² (the paper's value).
pub const STANDARD_GRAVITY: f64 = 9.81;

/// A ball, gravity, and the effects acting on it. The paper's model is [`Model::paper`].
#[derive(Debug, Clone)]
pub struct Model {
    /// The ball.
    pub ball: Ball,
    /// Gravitational acceleration, m/s².
    pub gravity: f64,
    effects: Vec<Box<dyn Effect>>,
}

impl Model {
    /// A model with no effects: the ball flies ballistically and passes through the surface.
    pub fn new(ball: Ball, gravity: f64) -> Model {
        Model {
            ball,
            gravity,
            effects: Vec::new(),
        }
    }

    /// The paper's hybrid model for the paper's ball: spring `k` (N/m), compression damping `b` (N·s/m),
    /// Coulomb friction `mu`.
    pub fn paper(k: f64, b: f64, mu: f64) -> Model {
        Model::new(Ball::TENNIS, STANDARD_GRAVITY)
            .with(LinearSpring { k })
            .with(LinearDamping { b })
            .with(Coulomb { mu })
    }

    /// Adds an effect (builder style).
    pub fn with(mut self, effect: impl Effect + 'static) -> Model {
        self.effects.push(Box::new(effect));
        self
    }

    /// Adds a boxed effect.
    pub fn push(&mut self, effect: Box<dyn Effect>) {
        self.effects.push(effect);
    }

    /// Removes the effect called `name`, returning it.
    pub fn remove(&mut self, name: &str) -> Option<Box<dyn Effect>> {
        let i = self.effects.iter().position(|e| e.name() == name)?;
        Some(self.effects.remove(i))
    }

    /// The effects, in the order they were added.
    pub fn effects(&self) -> &[Box<dyn Effect>] {
        &self.effects
    }

    /// The effect called `name`.
    pub fn effect(&self, name: &str) -> Option<&dyn Effect> {
        self.effects.iter().find(|e| e.name() == name).map(|e| e.as_ref())
    }

    /// Sets parameter `index` of effect `name`.
    pub fn set_param(&mut self, name: &str, index: usize, value: f64) -> Result<(), ModelError> {
        let known = self_names(&self.effects);
        let effect = self
            .effects
            .iter_mut()
            .find(|e| e.name() == name)
            .ok_or_else(|| ModelError::UnknownEffect {
                origin: "model".into(),
                name: name.into(),
                known,
            })?;
        let mut p = effect.params();
        if index >= p.len() {
            return Err(ModelError::UnknownParam {
                origin: "model".into(),
                effect: name.into(),
                param: format!("#{index}"),
                known: format!("{} parameters", p.len()),
            });
        }
        p[index] = value;
        effect.set_params(&p);
        Ok(())
    }

    /// Total Coulomb friction coefficient of the effects.
    pub fn friction_coefficient(&self) -> f64 {
        self.effects.iter().map(|e| e.friction_coefficient()).sum()
    }

    /// Moment of inertia about the centre, kg·m², including effects that change it.
    pub fn inertia(&self) -> f64 {
        self.ball.inertia(self.effects.iter().map(|e| e.inertia_shift()).sum())
    }
}

fn self_names(effects: &[Box<dyn Effect>]) -> String {
    effects
        .iter()
        .map(|e| e.name().to_string())
        .collect::<Vec<_>>()
        .join(", ")
}
