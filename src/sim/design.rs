//! Walker designs as data (TOML) and their validation; their scaling to another leg length
//! is in `similarity.rs`.

use std::path::Path;

use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::contact::ContactParams;
use super::control::Controller;
use super::effects::EffectSpec;
use super::error::SimError;
use super::model::{FootSection, GRAVITY_MPS2, Hardstop, Leg, Model};
use super::state::State;

/// Built-in designs: (name, path in the repository, text). Bundled so the binary works
/// from any directory. The `-ref` designs are ../shared/research/walker-models.json in this
/// schema: the models of the Drake cross-check (reports/drake-crosscheck.md).
pub const BUILTIN_DESIGNS: [(&str, &str, &str); 8] = [
    (
        "mugatu",
        "dataset/walkers/mugatu.toml",
        include_str!("../../dataset/walkers/mugatu.toml"),
    ),
    (
        "zippy",
        "dataset/walkers/zippy.toml",
        include_str!("../../dataset/walkers/zippy.toml"),
    ),
    (
        "zippy-spherical",
        "dataset/walkers/zippy-spherical.toml",
        include_str!("../../dataset/walkers/zippy-spherical.toml"),
    ),
    (
        "mugatu-lab",
        "dataset/walkers/mugatu-lab.toml",
        include_str!("../../dataset/walkers/mugatu-lab.toml"),
    ),
    (
        "mugatu-ref",
        "dataset/walkers/reference/mugatu-ref.toml",
        include_str!("../../dataset/walkers/reference/mugatu-ref.toml"),
    ),
    (
        "mugatu-ref-sap",
        "dataset/walkers/reference/mugatu-ref-sap.toml",
        include_str!("../../dataset/walkers/reference/mugatu-ref-sap.toml"),
    ),
    (
        "zippy-ref",
        "dataset/walkers/reference/zippy-ref.toml",
        include_str!("../../dataset/walkers/reference/zippy-ref.toml"),
    ),
    (
        "zippy-spherical-ref",
        "dataset/walkers/reference/zippy-spherical-ref.toml",
        include_str!("../../dataset/walkers/reference/zippy-spherical-ref.toml"),
    ),
];

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Geometry {
    pub leg_length_m: f64,
    pub body_length_m: f64,
    /// (R_X forward, R_Y lateral, R_Z vertical).
    pub foot_semi_axes_m: [f64; 3],
    /// Lateral distance of each leg's centre line from the mid-plane, / L.
    pub hip_half_width_over_l: f64,
    /// Lateral offset of each foot ellipsoid centre from the mid-plane, / L.
    pub foot_center_lateral_over_l: f64,
    /// Forward offset of each foot ellipsoid centre from the hip, / L.
    #[serde(default)]
    pub foot_center_forward_over_l: f64,
    /// Each foot is the outer part of its ellipsoid beyond the plane at this lateral
    /// distance from the mid-plane, / L (absent: the whole ellipsoid).
    #[serde(default)]
    pub foot_section_cut_over_l: Option<f64>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MassSpec {
    pub total_mass_kg: f64,
    /// Height of each leg's centre of mass above the ground when standing, / L.
    pub leg_com_height_over_l: f64,
    /// Forward offset of each leg's centre of mass from the hip, / L.
    #[serde(default)]
    pub leg_com_forward_over_l: f64,
    /// Edges (x, y, z) / L of the uniform box with each leg's inertia about its COM.
    pub leg_inertia_box_over_l: [f64; 3],
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    pub hydroelastic_modulus_pa: f64,
    /// Hunt–Crossley dissipation d [s/m] (p = p_e·(1 − d·vₙ)); absent: 0.
    #[serde(default)]
    pub hunt_crossley_dissipation_s_per_m: f64,
    pub friction_mu: f64,
    pub stiction_speed_mps: f64,
    /// Kelvin–Voigt relaxation time τ_d [s], Drake SAP's dissipation form (dissipative
    /// pressure −τ_d·(E/ρₙ)·vₙ over the whole patch); absent: 0 (Hunt–Crossley only).
    #[serde(default)]
    pub relaxation_time_s: f64,
    /// The friction cone the contact solver works with; absent: `coulomb`. Not written
    /// when `coulomb`, so a design's serialised form (and every key made from it) is the
    /// same as before the field existed.
    #[serde(default, skip_serializing_if = "FrictionCone::is_coulomb")]
    pub friction_cone: FrictionCone,
}

/// How the contact solver treats friction (see [`ContactParams::convex_coupling_time_s`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FrictionCone {
    /// Physical Coulomb friction: the normal force does not depend on the slip (the
    /// project's model, and Drake's `lagged` approximation).
    #[default]
    Coulomb,
    /// The convex (Anitescu-type) relaxation of Drake's SAP and `similar` approximations:
    /// a sliding contact pushes its bodies apart at μ·|slip|, so a scuffing foot glides.
    /// An engine's artefact, offered to model that engine's trials, not a robot.
    Convex,
}

impl FrictionCone {
    pub fn is_coulomb(&self) -> bool {
        *self == FrictionCone::Coulomb
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum ControlSpec {
    ServoSine {
        amplitude_deg: f64,
        frequency_hz: f64,
        /// Proportional gain / (m·g·L) [1/rad].
        kp_over_mgl: f64,
        /// Derivative gain / (m·g·L·√(L/g)) [s/rad · 1/s].
        kd_over_mgl_sqrt_l_over_g: f64,
        torque_limit_nm: f64,
    },
    BangBang {
        torque_nm: f64,
        frequency_hz: f64,
    },
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HardstopSpec {
    pub limit_deg: f64,
    /// Stiffness / (m·g·L) [1/rad].
    pub stiffness_over_mgl: f64,
    /// Damping / (m·g·L·√(L/g)).
    pub damping_over_mgl_sqrt_l_over_g: f64,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InitialSpec {
    /// Initial roll onto the right foot [deg] (a symmetric start never rocks).
    pub roll_deg: f64,
    /// Standard deviation of the seeded perturbation of roll, pitch and yaw [deg].
    pub seed_angle_sd_deg: f64,
    /// Standard deviation of the seeded angular velocity, / √(g/L).
    pub seed_rate_sd_over_sqrt_g_over_l: f64,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NumericsSpec {
    /// Integrator time step at this design's size [s] (scaled ∝ √L).
    pub time_step_s: f64,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CriteriaSpec {
    /// Walking if the steady forward speed exceeds this × √(gL).
    pub walk_speed_threshold_over_sqrt_gl: f64,
    /// Fallen if the hip point drops below this × L.
    pub fall_hip_height_over_l: f64,
    /// Fallen if |roll| of the hip frame exceeds this [deg].
    pub fall_roll_deg: f64,
    /// Fallen if |pitch| of the hip frame exceeds this [deg].
    pub fall_pitch_deg: f64,
    /// Whether the sign of the walking velocity is a prediction of the model (`forward`, the
    /// default) or set by the walker's first steps (`either`; see [`WalkingDirection`]).
    #[serde(default, skip_serializing_if = "WalkingDirection::is_forward")]
    pub walking_direction: WalkingDirection,
}

/// The design fields that change sign under the fore–aft mirror (x → −x): a walker with
/// the value v is the mirror image of the walker with −v. A design that walks either way has
/// them at 0 as written; where its start sets the direction, a calibrated value and its
/// negative walk mirror gaits of the walker's two starts, so the trials give the magnitude
/// and not the sign (`gap diagnose` says so).
pub const MIRROR_ODD_PATHS: [&str; 3] = [
    "geometry.foot_center_forward_over_l",
    "mass.leg_com_forward_over_l",
    "ground.slope_deg",
];

/// Which way a design walks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WalkingDirection {
    /// The model predicts the direction: a backward walk is a negative velocity.
    #[default]
    Forward,
    /// A fore–aft symmetric design (feet and leg COMs centred fore–aft, on the flat): the
    /// mirror image of a gait is a gait of the same drive half a period later, the free roll
    /// locks to the drive in either phase, and which of the two the walker takes is set by
    /// its first cycles — in both engines a few per cent of μ or of the drive frequency flip
    /// it (reports/gap-benchmark-drake-sap-convex/). The velocity is then compared as a
    /// speed |v| (the gap diagnosis, the walking criterion); on a sloped condition the
    /// slope sets the direction and the signed velocity is kept.
    Either,
}

impl WalkingDirection {
    pub fn is_forward(&self) -> bool {
        *self == WalkingDirection::Forward
    }
}

impl CriteriaSpec {
    /// The steady forward speed above which a walker of leg length `leg_length_m` walks
    /// [m/s]: the threshold × √(gL). Dimensionless, so the same at every size.
    pub fn walk_speed_threshold_mps(&self, leg_length_m: f64) -> f64 {
        self.walk_speed_threshold_over_sqrt_gl * (GRAVITY_MPS2 * leg_length_m).sqrt()
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct GroundSpec {
    /// Downhill slope along +x [deg] (0 = flat).
    #[serde(default)]
    pub slope_deg: f64,
}

/// A walker design (1× values of the robot it describes, SI units).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Design {
    pub name: String,
    #[serde(default)]
    pub description: String,
    pub geometry: Geometry,
    pub mass: MassSpec,
    pub contact: ContactSpec,
    pub control: ControlSpec,
    #[serde(default)]
    pub hardstop: Option<HardstopSpec>,
    pub initial: InitialSpec,
    pub numerics: NumericsSpec,
    pub criteria: CriteriaSpec,
    #[serde(default)]
    pub ground: GroundSpec,
    #[serde(default)]
    pub effects: Vec<EffectSpec>,
    /// Values of this file that are guesses ([CHOSEN], [REF], unpublished): what the gap
    /// diagnosis may calibrate, with their plausible ranges. Not physics: scaling, walks and
    /// the design hash of a study ignore them.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub uncertain: Vec<UncertainSpec>,
    /// How the gap diagnosis audits the values the file does *not* declare uncertain
    /// (`survey gap diagnose --audit-undeclared`). Not physics either.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub audit: Option<AuditSpec>,
    /// Where the design was read from (a file path, or a bundled design's path), for error
    /// messages about it; None for a design built in code. Not part of the design's data:
    /// never serialised, and ignored by equality.
    #[serde(skip)]
    pub origin: Option<DesignOrigin>,
}

/// Where a design came from (see [`Design::origin`]): compares equal to any other, so two
/// designs with the same values are equal wherever they were read.
#[derive(Clone, Debug, Default)]
pub struct DesignOrigin(pub String);

impl PartialEq for DesignOrigin {
    fn eq(&self, _: &DesignOrigin) -> bool {
        true
    }
}

impl std::fmt::Display for DesignOrigin {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

/// The undeclared-parameter audit of a design: every number of its physical sections
/// (geometry, mass, contact, control, hardstop, ground) that `[[uncertain]]` does not declare
/// is a suspect over a default range, except those listed here as known.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct AuditSpec {
    /// Values known well enough not to be suspects (measured, commanded, or without effect
    /// on the walks), each with why. A path covers what lies under it: `hardstop`, or
    /// `geometry.foot_semi_axes_m` for all three axes.
    #[serde(default)]
    pub fixed: Vec<FixedSpec>,
    /// An undeclared value may be off by up to this factor either way (log scale; default
    /// [`AUDIT_FACTOR`]).
    #[serde(default)]
    pub factor: Option<f64>,
    /// An undeclared offset whose file value is 0 (a field in leg lengths, `…_over_l`) may be
    /// off by up to ± this many leg lengths (default [`AUDIT_OFFSET_OVER_L`]).
    #[serde(default)]
    pub offset_over_l: Option<f64>,
}

/// A value the audit leaves alone, and why.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FixedSpec {
    pub path: String,
    pub why: String,
}

/// Default factor of the audit's range: an undeclared guess taken to be right within ×/÷ 2.
pub const AUDIT_FACTOR: f64 = 2.0;
/// Default half-range of an undeclared zero offset: 3 % of the leg length (5 mm at the
/// Mugatu's 1×), the scale of a build tolerance.
pub const AUDIT_OFFSET_OVER_L: f64 = 0.03;
/// The sections whose numbers describe the robot and its floor (the others set the start,
/// the integrator and the walk criteria: not suspects of a gap).
const AUDITED_SECTIONS: [&str; 6] = [
    "geometry", "mass", "contact", "control", "hardstop", "ground",
];

/// A number of a design file that is not known: where it is, how far it may be off, and why.
/// Give a `range` (plausible values, a uniform prior), an `sd` or `relative_sd` (a Gaussian
/// prior around the file's value; the range then defaults to ±3 sd), or both.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UncertainSpec {
    /// Dotted path of a number in the design file: `mass.leg_com_height_over_l`,
    /// `mass.leg_inertia_box_over_l[0]`, `effects[0].no_load_speed_rad_s`.
    pub path: String,
    /// Plausible values [min, max], in the field's unit.
    #[serde(default)]
    pub range: Option<[f64; 2]>,
    /// Prior standard deviation, in the field's unit.
    #[serde(default)]
    pub sd: Option<f64>,
    /// Prior standard deviation as a fraction of the file's value.
    #[serde(default)]
    pub relative_sd: Option<f64>,
    /// Calibrate on a log scale (for positive quantities spanning a factor of several).
    #[serde(default)]
    pub log: bool,
    /// Why the value is uncertain (its tag and the reasoning).
    pub why: String,
}

/// An [`UncertainSpec`] resolved against its design: the file's value, bounds and prior.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct UncertainParam {
    pub path: String,
    pub nominal: f64,
    pub lo: f64,
    pub hi: f64,
    /// Gaussian prior sd in the field's unit (None: uniform over [lo, hi]).
    pub prior_sd: Option<f64>,
    pub log: bool,
    pub why: String,
}

/// One step of a dotted path: a key, optionally indexed.
fn path_steps(path: &str) -> Option<Vec<(&str, Option<usize>)>> {
    path.split('.')
        .map(|seg| match seg.split_once('[') {
            None if !seg.is_empty() => Some((seg, None)),
            Some((k, rest)) if !k.is_empty() => {
                let i = rest.strip_suffix(']')?.parse().ok()?;
                Some((k, Some(i)))
            }
            _ => None,
        })
        .collect()
}

/// Every float of the audited sections of a design's TOML tree, by dotted path (arrays
/// indexed: `geometry.foot_semi_axes_m[0]`), in the tree's order.
fn leaf_paths(tree: &toml::Value) -> Vec<(String, f64)> {
    let mut out = Vec::new();
    for section in AUDITED_SECTIONS {
        let Some(t) = tree.get(section).and_then(|v| v.as_table()) else {
            continue;
        };
        for (key, v) in t {
            match v {
                toml::Value::Float(x) => out.push((format!("{section}.{key}"), *x)),
                toml::Value::Array(a) => {
                    for (i, x) in a.iter().enumerate() {
                        if let Some(x) = x.as_float() {
                            out.push((format!("{section}.{key}[{i}]"), x));
                        }
                    }
                }
                _ => {}
            }
        }
    }
    out
}

/// A `fixed` path covers a leaf: the same path, or a section or array above it.
fn covers(fixed: &str, leaf: &(String, f64)) -> bool {
    let p = leaf.0.as_str();
    p == fixed
        || p.strip_prefix(fixed)
            .is_some_and(|rest| rest.starts_with('.') || rest.starts_with('['))
}

/// The number at `path` of a TOML tree, mutably.
fn number_at<'a>(root: &'a mut toml::Value, path: &str) -> Result<&'a mut toml::Value, String> {
    let steps = path_steps(path).ok_or_else(|| {
        format!("`{path}` is not a dotted path such as mass.leg_com_height_over_l or mass.leg_inertia_box_over_l[0]")
    })?;
    let mut v = root;
    for (key, index) in steps {
        v = v
            .as_table_mut()
            .and_then(|t| t.get_mut(key))
            .ok_or_else(|| format!("`{path}`: no field `{key}` in the design"))?;
        if let Some(i) = index {
            v = v
                .as_array_mut()
                .and_then(|a| a.get_mut(i))
                .ok_or_else(|| format!("`{path}`: `{key}` has no element {i}"))?;
        }
    }
    match v {
        toml::Value::Float(_) | toml::Value::Integer(_) => Ok(v),
        _ => Err(format!("`{path}` is not a number")),
    }
}

/// A design field's check: `ok` and finite, or an error naming the field and the file.
struct FieldCheck<'a> {
    origin: &'a str,
}

impl FieldCheck<'_> {
    fn check(&self, field: &str, v: f64, ok: bool, why: &str) -> Result<(), SimError> {
        if ok && v.is_finite() {
            Ok(())
        } else {
            Err(SimError::InvalidValue {
                origin: self.origin.to_string(),
                field: field.to_string(),
                value: v.to_string(),
                reason: why.to_string(),
            })
        }
    }
}

impl Design {
    /// Parses and validates a design; `origin` (file name) appears in error messages.
    pub fn from_toml_str(text: &str, origin: &str) -> Result<Design, SimError> {
        let mut d: Design = toml::from_str(text).map_err(|e| SimError::Parse {
            origin: origin.to_string(),
            message: e.to_string(),
        })?;
        d.origin = Some(DesignOrigin(origin.to_string()));
        d.validate(origin)?;
        d.check_uncertain(origin)?;
        d.check_direction(origin)?;
        Ok(d)
    }

    /// Reads a design file.
    pub fn from_file(path: &Path) -> Result<Design, SimError> {
        let text = std::fs::read_to_string(path).map_err(|source| SimError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        Design::from_toml_str(&text, &path.display().to_string())
    }

    /// A bundled design by name (mugatu, zippy, zippy-spherical).
    pub fn builtin(name: &str) -> Result<Design, SimError> {
        let key = name.to_ascii_lowercase().replace('_', "-");
        let key = if key == "zippy-ellipsoidal" {
            "zippy".to_string()
        } else {
            key
        };
        for (n, path, text) in BUILTIN_DESIGNS {
            if n == key {
                return Design::from_toml_str(text, &format!("{path} (bundled)"));
            }
        }
        Err(SimError::UnknownDesign(name.to_string()))
    }

    /// A bundled name, or else a path to a TOML file.
    pub fn resolve(name_or_path: &str) -> Result<Design, SimError> {
        match Design::builtin(name_or_path) {
            Ok(d) => Ok(d),
            Err(SimError::UnknownDesign(_)) => {
                let p = Path::new(name_or_path);
                if p.exists() || name_or_path.ends_with(".toml") {
                    Design::from_file(p)
                } else {
                    Err(SimError::UnknownDesign(name_or_path.to_string()))
                }
            }
            Err(e) => Err(e),
        }
    }

    /// Whether this (scaled, set-up) design's direction is set by its start: it walks either
    /// way and stands on the flat (a slope sets the direction).
    pub fn walks_either_way(&self) -> bool {
        !self.criteria.walking_direction.is_forward() && self.ground.slope_deg == 0.0
    }

    /// A design that walks either way must be fore–aft symmetric as written ([`MIRROR_ODD_PATHS`] at 0) (checked where
    /// a file is read, not on calibrated copies: a knob may move a COM or the slope off the
    /// symmetry, and is then judged on the speed it gives).
    fn check_direction(&self, origin: &str) -> Result<(), SimError> {
        if self.criteria.walking_direction.is_forward() {
            return Ok(());
        }
        let ck = FieldCheck { origin };
        let why =
            "must be 0 for criteria.walking_direction = \"either\" (a fore–aft symmetric design)";
        for path in MIRROR_ODD_PATHS {
            let v = self.value_at(path)?;
            ck.check(path, v, v == 0.0, why)?;
        }
        Ok(())
    }

    fn validate(&self, origin: &str) -> Result<(), SimError> {
        let ck = FieldCheck { origin };
        self.validate_geometry(&ck)?;
        self.validate_mass(&ck)?;
        self.validate_contact(&ck)?;
        self.validate_control(&ck)?;
        self.validate_hardstop(&ck)?;
        self.validate_start(&ck)?;
        self.validate_criteria(&ck)?;
        for (n, e) in self.effects.iter().enumerate() {
            e.validate(origin, &format!("effects[{n}]"))?;
        }
        Ok(())
    }

    /// The geometry: positive lengths, a foot section within the foot.
    fn validate_geometry(&self, ck: &FieldCheck) -> Result<(), SimError> {
        let g = &self.geometry;
        ck.check(
            "geometry.leg_length_m",
            g.leg_length_m,
            g.leg_length_m > 0.0,
            "must be > 0",
        )?;
        ck.check(
            "geometry.body_length_m",
            g.body_length_m,
            g.body_length_m > 0.0,
            "must be > 0",
        )?;
        for (i, a) in g.foot_semi_axes_m.iter().enumerate() {
            ck.check(
                &format!("geometry.foot_semi_axes_m[{i}]"),
                *a,
                *a > 0.0,
                "must be > 0",
            )?;
        }
        ck.check(
            "geometry.hip_half_width_over_l",
            g.hip_half_width_over_l,
            g.hip_half_width_over_l >= 0.0,
            "must be ≥ 0",
        )?;
        ck.check(
            "geometry.foot_center_lateral_over_l",
            g.foot_center_lateral_over_l,
            true,
            "must be finite",
        )?;
        ck.check(
            "geometry.foot_center_forward_over_l",
            g.foot_center_forward_over_l,
            true,
            "must be finite",
        )?;
        if let Some(c) = g.foot_section_cut_over_l {
            ck.check(
                "geometry.foot_section_cut_over_l",
                c,
                c.abs() < 1.0,
                "must be within ±1",
            )?;
        }
        Ok(())
    }

    /// Mass, centre of mass and inertia box.
    fn validate_mass(&self, ck: &FieldCheck) -> Result<(), SimError> {
        let m = &self.mass;
        ck.check(
            "mass.total_mass_kg",
            m.total_mass_kg,
            m.total_mass_kg > 0.0,
            "must be > 0",
        )?;
        ck.check(
            "mass.leg_com_height_over_l",
            m.leg_com_height_over_l,
            m.leg_com_height_over_l > 0.0 && m.leg_com_height_over_l < 1.0,
            "must be in (0, 1)",
        )?;
        ck.check(
            "mass.leg_com_forward_over_l",
            m.leg_com_forward_over_l,
            true,
            "must be finite",
        )?;
        for (i, b) in m.leg_inertia_box_over_l.iter().enumerate() {
            ck.check(
                &format!("mass.leg_inertia_box_over_l[{i}]"),
                *b,
                *b > 0.0,
                "must be > 0",
            )?;
        }
        Ok(())
    }

    /// Contact: modulus, dissipation, relaxation, friction.
    fn validate_contact(&self, ck: &FieldCheck) -> Result<(), SimError> {
        let c = &self.contact;
        ck.check(
            "contact.hydroelastic_modulus_pa",
            c.hydroelastic_modulus_pa,
            c.hydroelastic_modulus_pa > 0.0 && c.hydroelastic_modulus_pa <= 1e12,
            "must be in (0, 1e12] Pa (1e12 is five times steel's Young's modulus)",
        )?;
        ck.check(
            "contact.hunt_crossley_dissipation_s_per_m",
            c.hunt_crossley_dissipation_s_per_m,
            c.hunt_crossley_dissipation_s_per_m >= 0.0,
            "must be ≥ 0",
        )?;
        ck.check(
            "contact.relaxation_time_s",
            c.relaxation_time_s,
            c.relaxation_time_s >= 0.0 && c.relaxation_time_s < 1.0,
            "must be in [0, 1) s",
        )?;
        ck.check(
            "contact.friction_mu",
            c.friction_mu,
            c.friction_mu >= 0.0,
            "must be ≥ 0",
        )?;
        ck.check(
            "contact.stiction_speed_mps",
            c.stiction_speed_mps,
            c.stiction_speed_mps > 0.0,
            "must be > 0",
        )?;
        Ok(())
    }

    /// The controller's amplitude, frequency, gains and torque.
    fn validate_control(&self, ck: &FieldCheck) -> Result<(), SimError> {
        match &self.control {
            ControlSpec::ServoSine {
                amplitude_deg,
                frequency_hz,
                kp_over_mgl,
                kd_over_mgl_sqrt_l_over_g,
                torque_limit_nm,
            } => {
                ck.check(
                    "control.amplitude_deg",
                    *amplitude_deg,
                    amplitude_deg.abs() < 90.0,
                    "must be within ±90",
                )?;
                ck.check(
                    "control.frequency_hz",
                    *frequency_hz,
                    *frequency_hz > 0.0,
                    "must be > 0",
                )?;
                ck.check(
                    "control.kp_over_mgl",
                    *kp_over_mgl,
                    *kp_over_mgl >= 0.0,
                    "must be ≥ 0",
                )?;
                ck.check(
                    "control.kd_over_mgl_sqrt_l_over_g",
                    *kd_over_mgl_sqrt_l_over_g,
                    *kd_over_mgl_sqrt_l_over_g >= 0.0,
                    "must be ≥ 0",
                )?;
                ck.check(
                    "control.torque_limit_nm",
                    *torque_limit_nm,
                    *torque_limit_nm >= 0.0,
                    "must be ≥ 0",
                )?;
            }
            ControlSpec::BangBang {
                torque_nm,
                frequency_hz,
            } => {
                ck.check(
                    "control.torque_nm",
                    *torque_nm,
                    *torque_nm >= 0.0,
                    "must be ≥ 0",
                )?;
                ck.check(
                    "control.frequency_hz",
                    *frequency_hz,
                    *frequency_hz > 0.0,
                    "must be > 0",
                )?;
            }
        }
        Ok(())
    }

    /// The hip limits, when the design has them.
    fn validate_hardstop(&self, ck: &FieldCheck) -> Result<(), SimError> {
        if let Some(h) = &self.hardstop {
            ck.check(
                "hardstop.limit_deg",
                h.limit_deg,
                h.limit_deg > 0.0 && h.limit_deg < 180.0,
                "must be in (0, 180)",
            )?;
            ck.check(
                "hardstop.stiffness_over_mgl",
                h.stiffness_over_mgl,
                h.stiffness_over_mgl > 0.0,
                "must be > 0",
            )?;
            ck.check(
                "hardstop.damping_over_mgl_sqrt_l_over_g",
                h.damping_over_mgl_sqrt_l_over_g,
                h.damping_over_mgl_sqrt_l_over_g >= 0.0,
                "must be ≥ 0",
            )?;
        }
        Ok(())
    }

    /// Initial conditions and the time step.
    fn validate_start(&self, ck: &FieldCheck) -> Result<(), SimError> {
        let i = &self.initial;
        ck.check(
            "initial.roll_deg",
            i.roll_deg,
            i.roll_deg.abs() < 45.0,
            "must be within ±45",
        )?;
        ck.check(
            "initial.seed_angle_sd_deg",
            i.seed_angle_sd_deg,
            i.seed_angle_sd_deg >= 0.0,
            "must be ≥ 0",
        )?;
        ck.check(
            "initial.seed_rate_sd_over_sqrt_g_over_l",
            i.seed_rate_sd_over_sqrt_g_over_l,
            i.seed_rate_sd_over_sqrt_g_over_l >= 0.0,
            "must be ≥ 0",
        )?;
        ck.check(
            "numerics.time_step_s",
            self.numerics.time_step_s,
            self.numerics.time_step_s > 0.0,
            "must be > 0",
        )?;
        Ok(())
    }

    /// Walk and fall criteria, and the ground slope.
    fn validate_criteria(&self, ck: &FieldCheck) -> Result<(), SimError> {
        let k = &self.criteria;
        ck.check(
            "criteria.walk_speed_threshold_over_sqrt_gl",
            k.walk_speed_threshold_over_sqrt_gl,
            k.walk_speed_threshold_over_sqrt_gl >= 0.0,
            "must be ≥ 0",
        )?;
        ck.check(
            "criteria.fall_hip_height_over_l",
            k.fall_hip_height_over_l,
            k.fall_hip_height_over_l > 0.0,
            "must be > 0",
        )?;
        ck.check(
            "criteria.fall_roll_deg",
            k.fall_roll_deg,
            k.fall_roll_deg > 0.0,
            "must be > 0",
        )?;
        ck.check(
            "criteria.fall_pitch_deg",
            k.fall_pitch_deg,
            k.fall_pitch_deg > 0.0,
            "must be > 0",
        )?;
        ck.check(
            "ground.slope_deg",
            self.ground.slope_deg,
            self.ground.slope_deg.abs() < 45.0,
            "must be within ±45",
        )?;
        Ok(())
    }

    /// The number at a dotted `path` of this design (see [`UncertainSpec::path`]).
    pub fn value_at(&self, path: &str) -> Result<f64, SimError> {
        let mut tree = self.to_tree()?;
        let v = number_at(&mut tree, path).map_err(|reason| self.bad_path(path, reason))?;
        Ok(v.as_float()
            .or_else(|| v.as_integer().map(|i| i as f64))
            .unwrap_or(f64::NAN))
    }

    /// This design with the number at `path` set to `value`, validated (an out-of-range
    /// value is an error naming the field, as in a file).
    pub fn with_value(&self, path: &str, value: f64) -> Result<Design, SimError> {
        self.with_values(&[(path, value)])
    }

    /// This design with several numbers set at once (one round trip through the TOML tree).
    pub fn with_values(&self, values: &[(&str, f64)]) -> Result<Design, SimError> {
        if values.is_empty() {
            return Ok(self.clone());
        }
        let mut tree = self.to_tree()?;
        for (path, value) in values {
            *number_at(&mut tree, path).map_err(|reason| self.bad_path(path, reason))? =
                toml::Value::Float(*value);
        }
        let mut d: Design = tree
            .try_into()
            .map_err(|e: toml::de::Error| SimError::Parse {
                origin: self.name.clone(),
                message: e.message().to_string(),
            })?;
        d.origin = self.origin.clone();
        d.validate(&self.name)?;
        Ok(d)
    }

    fn to_tree(&self) -> Result<toml::Value, SimError> {
        toml::Value::try_from(self).map_err(|e| SimError::Parse {
            origin: self.name.clone(),
            message: e.to_string(),
        })
    }

    fn bad_path(&self, path: &str, reason: String) -> SimError {
        SimError::InvalidValue {
            origin: self.name.clone(),
            field: path.to_string(),
            value: "—".into(),
            reason,
        }
    }

    /// The `[[uncertain]]` entries resolved: value, bounds and prior of each.
    pub fn uncertain_params(&self) -> Result<Vec<UncertainParam>, SimError> {
        self.uncertain
            .iter()
            .enumerate()
            .map(|(i, u)| self.resolve_uncertain(i, u, &self.name))
            .collect()
    }

    fn resolve_uncertain(
        &self,
        i: usize,
        u: &UncertainSpec,
        origin: &str,
    ) -> Result<UncertainParam, SimError> {
        let field = format!("uncertain[{i}] ({})", u.path);
        let bad = |value: String, reason: &str| SimError::InvalidValue {
            origin: origin.to_string(),
            field: field.clone(),
            value,
            reason: reason.to_string(),
        };
        let nominal = self
            .value_at(&u.path)
            .map_err(|e| bad(u.path.clone(), &e.to_string()))?;
        let prior_sd = match (u.sd, u.relative_sd) {
            (Some(_), Some(_)) => {
                return Err(bad(
                    "sd and relative_sd".into(),
                    "give one of them, not both",
                ));
            }
            (Some(sd), None) => Some(sd),
            (None, Some(r)) => {
                if nominal == 0.0 {
                    return Err(bad(
                        format!("relative_sd = {r}"),
                        "the file's value is 0: give an sd or a range instead",
                    ));
                }
                Some(r * nominal.abs())
            }
            (None, None) => None,
        };
        if let Some(sd) = prior_sd
            && !(sd > 0.0 && sd.is_finite())
        {
            return Err(bad(format!("sd = {sd}"), "must be finite and > 0"));
        }
        let [lo, hi] = match (u.range, prior_sd) {
            (Some(r), _) => r,
            (None, Some(sd)) => [nominal - 3.0 * sd, nominal + 3.0 * sd],
            (None, None) => {
                return Err(bad(
                    "no range, sd or relative_sd".into(),
                    "give a plausible range or a prior sd",
                ));
            }
        };
        if !(lo.is_finite() && hi.is_finite() && lo < hi) {
            return Err(bad(
                format!("[{lo}, {hi}]"),
                "range must be finite with min < max",
            ));
        }
        if !(lo <= nominal && nominal <= hi) {
            return Err(bad(
                format!("{nominal} outside [{lo}, {hi}]"),
                "the file's value must lie in its plausible range",
            ));
        }
        if u.log && lo <= 0.0 {
            return Err(bad(
                format!("[{lo}, {hi}]"),
                "a log-scale range must be > 0",
            ));
        }
        for end in [lo, hi] {
            self.with_value(&u.path, end).map_err(|e| {
                bad(
                    format!("{end}"),
                    &format!("the range's end is not a valid design: {e}"),
                )
            })?;
        }
        Ok(UncertainParam {
            path: u.path.clone(),
            nominal,
            lo,
            hi,
            prior_sd,
            log: u.log,
            why: u.why.clone(),
        })
    }

    fn check_uncertain(&self, origin: &str) -> Result<(), SimError> {
        let mut seen = std::collections::HashSet::new();
        for (i, u) in self.uncertain.iter().enumerate() {
            if !seen.insert(u.path.as_str()) {
                return Err(SimError::InvalidValue {
                    origin: origin.to_string(),
                    field: format!("uncertain[{i}]"),
                    value: u.path.clone(),
                    reason: "the same path is declared twice".into(),
                });
            }
            if u.why.trim().is_empty() {
                return Err(SimError::InvalidValue {
                    origin: origin.to_string(),
                    field: format!("uncertain[{i}].why"),
                    value: "\"\"".into(),
                    reason: "say why the value is uncertain (its tag and reasoning)".into(),
                });
            }
            self.resolve_uncertain(i, u, origin)?;
        }
        self.check_audit(origin)
    }

    fn check_audit(&self, origin: &str) -> Result<(), SimError> {
        let Some(a) = &self.audit else {
            return Ok(());
        };
        let bad = |field: String, value: String, reason: &str| SimError::InvalidValue {
            origin: origin.to_string(),
            field,
            value,
            reason: reason.to_string(),
        };
        let ck = FieldCheck { origin };
        if let Some(f) = a.factor {
            ck.check("audit.factor", f, f > 1.0, "must be finite and > 1")?;
        }
        if let Some(o) = a.offset_over_l {
            ck.check("audit.offset_over_l", o, o > 0.0, "must be finite and > 0")?;
        }
        let tree = self.to_tree()?;
        for (i, f) in a.fixed.iter().enumerate() {
            if f.why.trim().is_empty() {
                return Err(bad(
                    format!("audit.fixed[{i}].why"),
                    "\"\"".into(),
                    "say why the value is known (its tag and reasoning)",
                ));
            }
            if !leaf_paths(&tree).iter().any(|p| covers(&f.path, p)) {
                return Err(bad(
                    format!("audit.fixed[{i}].path"),
                    f.path.clone(),
                    "names no number of the design's geometry, mass, contact, control, hardstop or ground",
                ));
            }
        }
        Ok(())
    }

    /// The numbers the design does not declare uncertain, as the undeclared-parameter audit
    /// weighs them: every number of the physical sections that is neither declared
    /// (`[[uncertain]]`) nor listed known (`[audit] fixed`), over ×/÷ the audit's factor
    /// around the file's value (log scale), or ± its offset for a zero `…_over_l` offset.
    /// A range end that is not a valid design is pulled halfway toward the file's value
    /// (up to 4 times; then the file's value is that end). Zero values of other units and
    /// integers are left out (no scale to take).
    pub fn undeclared_params(&self) -> Result<Vec<UncertainParam>, SimError> {
        let spec = self.audit.clone().unwrap_or_default();
        let factor = spec.factor.unwrap_or(AUDIT_FACTOR);
        let offset = spec.offset_over_l.unwrap_or(AUDIT_OFFSET_OVER_L);
        let tree = self.to_tree()?;
        let mut out = Vec::new();
        for (path, nominal) in leaf_paths(&tree) {
            // The 1× leg length is the size every other value scales from, and the trials
            // state each condition's own: not a suspect.
            if path == "geometry.leg_length_m"
                || self.uncertain.iter().any(|u| u.path == path)
                || spec
                    .fixed
                    .iter()
                    .any(|f| covers(&f.path, &(path.clone(), nominal)))
            {
                continue;
            }
            let (lo, hi, log) = if nominal > 0.0 {
                (nominal / factor, nominal * factor, true)
            } else if nominal < 0.0 {
                (nominal * factor, nominal / factor, false)
            } else if path.ends_with("_over_l") {
                (-offset, offset, false)
            } else {
                continue;
            };
            let valid_end = |end: f64| {
                let mut v = end;
                for _ in 0..5 {
                    if self.with_value(&path, v).is_ok() {
                        return v;
                    }
                    v = 0.5 * (v + nominal);
                }
                nominal
            };
            let (lo, hi) = (valid_end(lo), valid_end(hi));
            if lo >= hi {
                continue;
            }
            out.push(UncertainParam {
                why: format!(
                    "undeclared: not in the design's [[uncertain]]; audited over [{lo:.4}, {hi:.4}]"
                ),
                path,
                nominal,
                lo,
                hi,
                prior_sd: None,
                log,
            });
        }
        Ok(out)
    }

    /// The file (or bundled path) the design was read from, else its name: what an error
    /// about the design names.
    pub fn origin_name(&self) -> String {
        self.origin
            .as_ref()
            .map(|o| o.0.clone())
            .unwrap_or_else(|| self.name.clone())
    }

    pub fn leg_length_m(&self) -> f64 {
        self.geometry.leg_length_m
    }

    /// m·g·L [N·m], the natural torque unit of the design.
    pub fn mgl_nm(&self) -> f64 {
        self.mass.total_mass_kg * GRAVITY_MPS2 * self.geometry.leg_length_m
    }

    /// The same robot carrying a payload (or weighing other than its file says): total mass
    /// `mass_kg`, spread like the legs' own mass, with the hip servo's gains and the
    /// hardstop unchanged in SI. The file gives them per m·g·L (the rule a design follows
    /// across sizes); a payload on one robot does not stiffen its servo or its stop, so their
    /// ratios to m·g·L fall as the mass grows.
    pub fn carrying(&mut self, mass_kg: f64) {
        let keep = self.mass.total_mass_kg / mass_kg;
        self.mass.total_mass_kg = mass_kg;
        if let ControlSpec::ServoSine {
            kp_over_mgl,
            kd_over_mgl_sqrt_l_over_g,
            ..
        } = &mut self.control
        {
            *kp_over_mgl *= keep;
            *kd_over_mgl_sqrt_l_over_g *= keep;
        }
        if let Some(h) = &mut self.hardstop {
            h.stiffness_over_mgl *= keep;
            h.damping_over_mgl_sqrt_l_over_g *= keep;
        }
    }

    /// The rigid-body model, with the contact effects of `effects` applied to its contact
    /// parameters.
    pub fn model(&self) -> Model {
        let l = self.geometry.leg_length_m;
        let g = &self.geometry;
        let m = &self.mass;
        let leg_mass = 0.5 * m.total_mass_kg;
        let b = m.leg_inertia_box_over_l.map(|x| x * l);
        let inertia = Matrix3::from_diagonal(&Vector3::new(
            leg_mass / 12.0 * (b[1] * b[1] + b[2] * b[2]),
            leg_mass / 12.0 * (b[0] * b[0] + b[2] * b[2]),
            leg_mass / 12.0 * (b[0] * b[0] + b[1] * b[1]),
        ));
        let semi = Vector3::new(
            g.foot_semi_axes_m[0],
            g.foot_semi_axes_m[1],
            g.foot_semi_axes_m[2],
        );
        let leg = |side: f64| Leg {
            mass_kg: leg_mass,
            com_m: Vector3::new(
                m.leg_com_forward_over_l * l,
                side * g.hip_half_width_over_l * l,
                -(1.0 - m.leg_com_height_over_l) * l,
            ),
            inertia_com_kgm2: inertia,
            foot_center_m: Vector3::new(
                g.foot_center_forward_over_l * l,
                side * g.foot_center_lateral_over_l * l,
                -l + semi.z,
            ),
            foot_semi_axes_m: semi,
            foot_section: g.foot_section_cut_over_l.map(|c| FootSection {
                normal: Vector3::new(0.0, side, 0.0),
                offset_m: c * l,
            }),
        };
        let mgl = self.mgl_nm();
        let tl = (l / GRAVITY_MPS2).sqrt();
        let slope = self.ground.slope_deg.to_radians();
        let mut contact = ContactParams {
            modulus_pa: self.contact.hydroelastic_modulus_pa,
            dissipation_s_per_m: self.contact.hunt_crossley_dissipation_s_per_m,
            friction_mu: self.contact.friction_mu,
            stiction_speed_mps: self.contact.stiction_speed_mps,
            relaxation_time_s: self.contact.relaxation_time_s,
            // SAP's normal impulse reacts to vₙ − μ|v_t| through its whole implicit normal
            // coefficient k·(δt + τ) (Castro et al. 2022, the cone projection's sliding
            // branch with R_t ≪ R_n), so the coupling time is τ + δt.
            convex_coupling_time_s: match self.contact.friction_cone {
                FrictionCone::Coulomb => 0.0,
                FrictionCone::Convex => self.contact.relaxation_time_s + self.numerics.time_step_s,
            },
            rolling_resistance_m: 0.0,
            // The angular counterpart of the stiction speed: a foot rolling on its leg
            // (radius ~ L) at v_s.
            rolling_resistance_rate_rad_s: self.contact.stiction_speed_mps / l,
        };
        for e in &self.effects {
            e.apply_to_contact(&mut contact, l);
        }
        Model {
            legs: [leg(1.0), leg(-1.0)],
            contact,
            hardstop: self.hardstop.as_ref().map(|h| Hardstop {
                limit_rad: h.limit_deg.to_radians(),
                stiffness_nm_per_rad: h.stiffness_over_mgl * mgl,
                damping_nms_per_rad: h.damping_over_mgl_sqrt_l_over_g * mgl * tl,
            }),
            gravity_mps2: Vector3::new(slope.sin(), 0.0, -slope.cos()) * GRAVITY_MPS2,
            ground_contact: true,
        }
    }

    /// The hip controller.
    pub fn controller(&self) -> Controller {
        let mgl = self.mgl_nm();
        let tl = (self.geometry.leg_length_m / GRAVITY_MPS2).sqrt();
        match self.control {
            ControlSpec::ServoSine {
                amplitude_deg,
                frequency_hz,
                kp_over_mgl,
                kd_over_mgl_sqrt_l_over_g,
                torque_limit_nm,
            } => Controller::ServoSine {
                amplitude_rad: amplitude_deg.to_radians(),
                frequency_hz,
                kp_nm_per_rad: kp_over_mgl * mgl,
                kd_nms_per_rad: kd_over_mgl_sqrt_l_over_g * mgl * tl,
                torque_limit_nm,
            },
            ControlSpec::BangBang {
                torque_nm,
                frequency_hz,
            } => Controller::BangBang {
                torque_nm,
                frequency_hz,
            },
        }
    }

    /// Initial state: at rest, legs together, rolled `initial.roll_deg` onto the right foot,
    /// standing on the ground with the static sinkage of one foot carrying the whole weight.
    /// A seed perturbs roll, pitch, yaw and the angular velocity deterministically (ChaCha8).
    pub fn initial_state(&self, model: &Model, seed: Option<u64>) -> State {
        let l = self.geometry.leg_length_m;
        let mut roll = self.initial.roll_deg.to_radians();
        let mut pitch = 0.0;
        let mut yaw = 0.0;
        let mut omega = Vector3::zeros();
        if let Some(seed) = seed {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            // Uniform on ±√3·sd has standard deviation sd.
            let a = self.initial.seed_angle_sd_deg.to_radians() * 3f64.sqrt();
            let w = self.initial.seed_rate_sd_over_sqrt_g_over_l
                * (GRAVITY_MPS2 / l).sqrt()
                * 3f64.sqrt();
            let mut u = |x: f64| {
                if x > 0.0 {
                    rng.random_range(-x..x)
                } else {
                    0.0
                }
            };
            roll += u(a);
            pitch += u(a);
            yaw += u(a);
            omega = Vector3::new(u(w), u(w), u(w));
        }
        let orientation = UnitQuaternion::from_euler_angles(roll, pitch, yaw);
        let r = *orientation.to_rotation_matrix().matrix();
        let hip_z = model.touch_height_m(&r);
        let sink = model.single_foot_sinkage_m();
        State {
            hip_position_m: Vector3::new(0.0, 0.0, hip_z - sink),
            orientation,
            hip_angle_rad: 0.0,
            hip_velocity_mps: Vector3::zeros(),
            angular_velocity_rad_s: omega,
            hip_rate_rad_s: 0.0,
        }
    }
}
