//! Which rows and columns of a compiled survey table a fit uses: the survey variables
//! ([`Var`]), the groups of robots fitted together ([`Group`]), the Table 2 pairs and the
//! points of a group. They live here, under the analyses, so that the validator's outlier
//! rule can select the same data without depending on `analysis/`.

use serde::Serialize;

use super::{RobotClass, SpeedKind, SurveyRow, SurveyTable};
use crate::regression;

/// A survey variable, in the paper's words: the three sizes of Table 2 and the speeds,
/// one variable per kind of speed (speeds of different kinds are not comparable).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Var {
    LegLength,
    BodyLength,
    Mass,
    SpeedTop,
    SpeedTypical,
    SpeedWalking,
    SpeedRunning,
    /// The survey's speeds of unstated kind (releases up to 1.4.0).
    SpeedUnstated,
}

impl Var {
    pub const ALL: [Var; 8] = [
        Var::LegLength,
        Var::BodyLength,
        Var::Mass,
        Var::SpeedTop,
        Var::SpeedTypical,
        Var::SpeedWalking,
        Var::SpeedRunning,
        Var::SpeedUnstated,
    ];
    /// The sizes of Table 2: leg length, body length, mass.
    pub const SIZES: [Var; 3] = [Var::LegLength, Var::BodyLength, Var::Mass];

    /// The speed variable of a kind.
    pub fn speed(kind: SpeedKind) -> Var {
        match kind {
            SpeedKind::Top => Var::SpeedTop,
            SpeedKind::Typical => Var::SpeedTypical,
            SpeedKind::Walking => Var::SpeedWalking,
            SpeedKind::Running => Var::SpeedRunning,
            SpeedKind::Unstated => Var::SpeedUnstated,
        }
    }
    /// The kind of a speed variable (None for the sizes).
    pub fn speed_kind(self) -> Option<SpeedKind> {
        match self {
            Var::LegLength | Var::BodyLength | Var::Mass => None,
            Var::SpeedTop => Some(SpeedKind::Top),
            Var::SpeedTypical => Some(SpeedKind::Typical),
            Var::SpeedWalking => Some(SpeedKind::Walking),
            Var::SpeedRunning => Some(SpeedKind::Running),
            Var::SpeedUnstated => Some(SpeedKind::Unstated),
        }
    }
    /// Position in [`Var::ALL`].
    pub fn index(self) -> usize {
        self as usize
    }
    /// Column of the compiled table.
    pub fn field(self) -> &'static str {
        match self {
            Var::LegLength => "leg_length_m",
            Var::BodyLength => "body_length_m",
            Var::Mass => "mass_kg",
            v => v.speed_kind().map(SpeedKind::field).unwrap_or_default(),
        }
    }
    pub fn as_str(self) -> &'static str {
        match self {
            Var::LegLength => "leg_length",
            Var::BodyLength => "body_length",
            Var::Mass => "mass",
            Var::SpeedTop => "speed_top",
            Var::SpeedTypical => "speed_typical",
            Var::SpeedWalking => "speed_walking",
            Var::SpeedRunning => "speed_running",
            Var::SpeedUnstated => "speed_unstated",
        }
    }
    /// A variable by name (`mass`, `speed_top`) or column (`mass_kg`, `speed_top_mps`).
    pub fn parse(s: &str) -> Option<Var> {
        Var::ALL
            .into_iter()
            .find(|v| v.as_str() == s || v.field() == s)
    }
    /// Symbol in the paper (L, L_B, m, v).
    pub fn symbol(self) -> &'static str {
        match self {
            Var::LegLength => "L",
            Var::BodyLength => "L_B",
            Var::Mass => "m",
            _ => "v",
        }
    }
    pub fn unit(self) -> &'static str {
        match self {
            Var::LegLength | Var::BodyLength => "m",
            Var::Mass => "kg",
            _ => "m/s",
        }
    }
    /// The variable in words, for tables and axes ("top speed", "leg length").
    pub fn label(self) -> &'static str {
        match self {
            Var::LegLength => "leg length",
            Var::BodyLength => "body length",
            Var::Mass => "mass",
            Var::SpeedTop => "top speed",
            Var::SpeedTypical => "typical speed",
            Var::SpeedWalking => "walking speed",
            Var::SpeedRunning => "running speed",
            Var::SpeedUnstated => "speed of unstated kind",
        }
    }
}

/// The (x, y) pairs of Table 2, in the paper's row order.
pub const TABLE2_PAIRS: [(Var, Var); 3] = [
    (Var::LegLength, Var::BodyLength),
    (Var::LegLength, Var::Mass),
    (Var::BodyLength, Var::Mass),
];

/// A group of robots fitted together: one class, or all fitted robots.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Group {
    Class(RobotClass),
    All,
}

impl Group {
    /// The paper's Table 2 columns.
    pub const TABLE2: [Group; 5] = [
        Group::Class(RobotClass::LowerBiped),
        Group::Class(RobotClass::FullBiped),
        Group::Class(RobotClass::Quadruped),
        Group::Class(RobotClass::Hexapod),
        Group::All,
    ];
    pub fn as_str(self) -> &'static str {
        match self {
            Group::Class(c) => c.as_str(),
            Group::All => "all",
        }
    }
    pub fn label(self) -> &'static str {
        match self {
            Group::Class(c) => c.label(),
            Group::All => "All",
        }
    }
    pub fn parse(s: &str) -> Option<Group> {
        if s == "all" {
            Some(Group::All)
        } else {
            RobotClass::parse(s)
                .filter(|c| *c != RobotClass::Hybrid)
                .map(Group::Class)
        }
    }
    pub fn contains(self, row: &SurveyRow) -> bool {
        self.includes(row.class, row.fit)
    }
    /// Whether a robot of `class`, fitted or not, belongs to the group's fit.
    pub fn includes(self, class: RobotClass, fit: bool) -> bool {
        fit && match self {
            Group::Class(c) => class == c,
            Group::All => RobotClass::FITTED.contains(&class),
        }
    }
}

impl std::fmt::Display for Group {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl Serialize for Group {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.as_str())
    }
}

/// The fitted robots of a group that have both variables, as (id, x, y).
pub fn points(table: &SurveyTable, group: Group, x: Var, y: Var) -> Vec<(String, f64, f64)> {
    table
        .rows
        .iter()
        .filter(|r| group.contains(r))
        .filter_map(|r| Some((r.id.clone(), r.number(x.field())?, r.number(y.field())?)))
        .collect()
}

/// The fitted robots of a group with both variables, raw and as log10 (checked once:
/// a non-positive or non-finite value is an error naming its index).
#[derive(Debug, Clone)]
pub struct LogPoints {
    pub ids: Vec<String>,
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    pub lx: Vec<f64>,
    pub ly: Vec<f64>,
}

/// [`points`] with their logarithms.
pub fn log_points(
    table: &SurveyTable,
    group: Group,
    x: Var,
    y: Var,
) -> Result<LogPoints, regression::RegressionError> {
    let pts = points(table, group, x, y);
    let (xs, ys): (Vec<f64>, Vec<f64>) = pts.iter().map(|p| (p.1, p.2)).unzip();
    Ok(LogPoints {
        lx: regression::log10_checked(&xs, x.as_str())?,
        ly: regression::log10_checked(&ys, y.as_str())?,
        ids: pts.into_iter().map(|p| p.0).collect(),
        x: xs,
        y: ys,
    })
}
