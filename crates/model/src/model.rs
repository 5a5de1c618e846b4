//! A model: a ball, gravity and a list of effects.

use crate::effects::{Context, Coulomb, Effect, LinearDamping, LinearSpring, Loads, Phase};
use crate::{Ball, ModelError, State};

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

    /// Total tangential compliance of the contact patch, m/N (0: rigid, the Coulomb contact).
    pub fn tangential_compliance(&self) -> f64 {
        self.effects.iter().map(|e| e.tangential_compliance()).sum()
    }

    /// Total damping of the contact patch's tangential spring, N·s/m.
    pub fn tangential_damping(&self) -> f64 {
        self.effects.iter().map(|e| e.tangential_damping()).sum()
    }

    /// True if an effect reads the contact's history (`u_t`, `∫δ dt`) or the patch is compliant: the
    /// simulator then integrates the history with the state.
    pub fn uses_contact_history(&self) -> bool {
        self.effects.iter().any(|e| e.uses_contact_history())
    }

    /// Moment of inertia about the centre, kg·m², including effects that change it.
    pub fn inertia(&self) -> f64 {
        self.ball.inertia(self.effects.iter().map(|e| e.inertia_shift()).sum())
    }

    /// The loads the effects add on the ball in flight at `state` on a surface inclined by `incline` rad
    /// (air drag, a custom flight term): all zero when the flight is ballistic. Lets a fit tell whether a
    /// measured ballistic arc is still this model's flight.
    pub fn flight_loads(&self, state: &State, incline: f64) -> Loads {
        let ctx = Context::of(0.0, state, Phase::Flight, &self.ball, self.gravity, incline);
        let mut total = Loads::default();
        for e in &self.effects {
            total.add(&e.loads(&ctx));
        }
        total
    }
}

fn self_names(effects: &[Box<dyn Effect>]) -> String {
    effects
        .iter()
        .map(|e| e.name().to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::effects::QuadraticDrag;

    #[test]
    fn flight_loads_are_zero_for_the_paper_model_and_oppose_the_velocity_with_drag() {
        let state = State {
            y: 0.1,
            vx: 1.0,
            vy: -3.0,
            ..State::default()
        };
        let paper = Model::paper(25_650.0, 14.0, 0.5);
        assert_eq!(paper.flight_loads(&state, 0.2), Loads::default());
        let drag = paper.with(QuadraticDrag { cd: 0.55, rho: 1.204 });
        let l = drag.flight_loads(&state, 0.2);
        let r = drag.ball.radius_m;
        let c = 0.5 * 1.204 * 0.55 * std::f64::consts::PI * r * r * 10f64.sqrt();
        assert!(
            (l.force_x + c).abs() < 1e-15 && (l.force_y - 3.0 * c).abs() < 1e-15,
            "{l:?}"
        );
    }
}
