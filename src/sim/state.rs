//! The walker's generalized state and the kinematics of one configuration: the data that
//! the model, the effects and the walk all read (coordinates explained in `model.rs`).

use nalgebra::{Matrix3, SMatrix, SVector, UnitQuaternion, Vector3};

/// 7-vector of generalized velocities / forces (v, ω, q̇).
pub type Vector7 = SVector<f64, 7>;
/// 7×7 matrix (mass, damping).
pub type Matrix7 = SMatrix<f64, 7, 7>;

/// Generalized state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct State {
    /// Hip point, world [m].
    pub hip_position_m: Vector3<f64>,
    /// Orientation of the left leg (leg → world).
    pub orientation: UnitQuaternion<f64>,
    /// Hip angle q [rad].
    pub hip_angle_rad: f64,
    /// Hip point velocity, world [m/s].
    pub hip_velocity_mps: Vector3<f64>,
    /// Left-leg angular velocity in the left-leg frame [rad/s].
    pub angular_velocity_rad_s: Vector3<f64>,
    /// Hip rate q̇ [rad/s].
    pub hip_rate_rad_s: f64,
}

impl State {
    /// Generalized velocity vector ν.
    #[inline]
    pub fn velocity(&self) -> Vector7 {
        let v = self.hip_velocity_mps;
        let w = self.angular_velocity_rad_s;
        Vector7::from_column_slice(&[v.x, v.y, v.z, w.x, w.y, w.z, self.hip_rate_rad_s])
    }

    #[inline]
    pub(super) fn set_velocity(&mut self, nu: &Vector7) {
        self.hip_velocity_mps = Vector3::new(nu[0], nu[1], nu[2]);
        self.angular_velocity_rad_s = Vector3::new(nu[3], nu[4], nu[5]);
        self.hip_rate_rad_s = nu[6];
    }

    /// True when every component is finite.
    pub fn is_finite(&self) -> bool {
        self.velocity().iter().all(|x| x.is_finite())
            && self.hip_position_m.iter().all(|x| x.is_finite())
            && self.orientation.coords.iter().all(|x| x.is_finite())
            && self.hip_angle_rad.is_finite()
    }
}

/// Kinematic quantities of one configuration.
#[derive(Clone, Copy, Debug)]
pub struct Kinematics {
    /// Leg rotations (leg → world), [left, right].
    pub rot: [Matrix3<f64>; 2],
    /// Hip axis in world.
    pub axis_w: Vector3<f64>,
    /// World angular velocities of the legs.
    pub omega_w: [Vector3<f64>; 2],
    /// Centre-of-mass positions relative to the hip point, world.
    pub com_offset_w: [Vector3<f64>; 2],
}
