//! How each end of the rod is held (issue 52): clamped, pinned or free.
//!
//! - `Clamped`: the gripper holds the end's position and angle (the default everywhere, and
//!   the only condition of the paper).
//! - `Pinned`: the position is held, the moment is zero, κ = 0 at that end, its angle is free
//!   (a hook, a pin joint, a pulley's axle).
//! - `Free`: no force and no moment, n = 0 and κ = 0 (a cable hanging from one gripper).
//!
//! The base carries the rod's frame, so it is clamped or pinned; a free tip has no target.

use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// What one end of the rod holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum EndCondition {
    /// Position and angle held (the default).
    #[default]
    Clamped,
    /// Position held, moment zero: the end's angle is free.
    Pinned,
    /// Nothing held: no force, no moment.
    Free,
}

impl EndCondition {
    /// The name used in requests: `"clamped"`, `"pinned"` or `"free"`.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Clamped => "clamped",
            Self::Pinned => "pinned",
            Self::Free => "free",
        }
    }
}

impl fmt::Display for EndCondition {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Why a pair of end conditions or a value was refused.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum EndsError {
    /// Not one of the three names.
    #[error("{field} must be \"clamped\", \"pinned\" or \"free\" (got {got:?})")]
    UnknownName {
        /// The field that carried it.
        field: &'static str,
        /// What it said.
        got: String,
    },
    /// A combination the model does not pose.
    #[error("{field}: {why}")]
    Unsupported {
        /// The field to change.
        field: &'static str,
        /// Why.
        why: &'static str,
    },
}

impl FromStr for EndCondition {
    type Err = EndsError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "clamped" => Ok(Self::Clamped),
            "pinned" => Ok(Self::Pinned),
            "free" => Ok(Self::Free),
            other => Err(EndsError::UnknownName {
                field: "end condition",
                got: other.into(),
            }),
        }
    }
}

/// The conditions at the base and at the tip.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct HeldEnds {
    base: EndCondition,
    tip: EndCondition,
}

impl HeldEnds {
    /// Both ends clamped: the paper's rod.
    pub const CLAMPED: HeldEnds = HeldEnds {
        base: EndCondition::Clamped,
        tip: EndCondition::Clamped,
    };

    /// The pair (`base`, `tip`). The base holds the rod (clamped or pinned); a pinned base with
    /// a free tip holds nothing against rotation (a free pendulum), so it is refused too.
    ///
    /// ```
    /// use rod_ig_core::ends::{EndCondition::*, HeldEnds};
    /// assert!(HeldEnds::new(Clamped, Free).is_ok());
    /// assert!(HeldEnds::new(Pinned, Pinned).is_ok());
    /// assert!(HeldEnds::new(Free, Clamped).is_err());
    /// ```
    pub fn new(base: EndCondition, tip: EndCondition) -> Result<Self, EndsError> {
        if base == EndCondition::Free {
            return Err(EndsError::Unsupported {
                field: "base_condition",
                why: "the base gripper holds the rod: \"clamped\" or \"pinned\" (a cable held \
                      by its tip alone is the same cable with base and tip swapped)",
            });
        }
        if base == EndCondition::Pinned && tip == EndCondition::Free {
            return Err(EndsError::Unsupported {
                field: "tip_condition",
                why: "a rod pinned at its base with a free tip is a free pendulum: nothing \
                      holds its angle; clamp the base or hold the tip",
            });
        }
        Ok(Self { base, tip })
    }

    /// The base's condition.
    pub fn base(&self) -> EndCondition {
        self.base
    }

    /// The tip's condition.
    pub fn tip(&self) -> EndCondition {
        self.tip
    }

    /// True for the paper's rod (both clamped).
    pub fn both_clamped(&self) -> bool {
        *self == Self::CLAMPED
    }
}
