//! The state types the integrators carry.

/// A state the integrators can carry: a `Vec` or a fixed-size array.
pub trait StateVec:
    differential_equations::traits::State<f64> + AsRef<[f64]> + AsMut<[f64]>
{
}
impl<Y: differential_equations::traits::State<f64> + AsRef<[f64]> + AsMut<[f64]>> StateVec for Y {}
