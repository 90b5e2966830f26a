//! A transform buffer with tf2's semantics (`tf2::BufferCore`), for the node's TF support
//! (issue 43, item 1): what `/tf` and `/tf_static` say, and the transform between two frames at
//! a time. No DDS here; the node feeds it and asks it.
//!
//! As tf2 does:
//! - each frame has one parent at a time; a dynamic frame keeps its transforms of the last
//!   `cache` seconds (tf2's default: 10 s) and a lookup between two stamps interpolates
//!   (translation linearly, rotation by slerp); outside its stamps a lookup is an
//!   extrapolation error, never a guess;
//! - a static frame holds one transform, valid at every time;
//! - time `None` (tf2's `TimePointZero`) asks for the latest time at which every link of the
//!   chain is known;
//! - frame ids are not empty and do not start with `/`; a chain longer than
//!   [`MAX_GRAPH_DEPTH`] is a loop;
//! - transforms with non-finite values or a quaternion of norm far from 1 are refused.

use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};
use std::collections::{HashMap, VecDeque};

/// Longest chain from a frame to its root (tf2's `MAX_GRAPH_DEPTH`): beyond it, a loop.
pub const MAX_GRAPH_DEPTH: usize = 1000;
/// How far the norm of a received quaternion may be from 1 (tf2 refuses beyond 1e-2 and
/// normalises within).
const QUATERNION_NORM_TOLERANCE: f64 = 1e-2;

/// Time in nanoseconds (ROS time of the message stamps).
pub type Nanos = i64;

/// One transform as `/tf` carries it: the pose of `child` in `parent` at `stamp`.
#[derive(Clone, Debug, PartialEq)]
pub struct StampedTransform {
    /// The parent frame (`header.frame_id`).
    pub parent: String,
    /// The child frame (`child_frame_id`).
    pub child: String,
    /// `header.stamp`.
    pub stamp: Nanos,
    /// Translation (m).
    pub translation: [f64; 3],
    /// Rotation quaternion (x, y, z, w).
    pub rotation: [f64; 4],
}

/// Why a transform was not stored.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum InsertError {
    /// A frame id tf2 rejects.
    #[error("frame id {0:?} is empty or starts with '/'")]
    InvalidFrameId(String),
    /// The frame would be its own parent.
    #[error("frame {0:?} cannot be its own parent")]
    SelfParent(String),
    /// Non-finite translation or rotation, or a quaternion far from unit norm.
    #[error("transform {parent} -> {child} is not finite or its quaternion is not unit")]
    InvalidTransform {
        /// Parent frame.
        parent: String,
        /// Child frame.
        child: String,
    },
}

/// Why a lookup failed: each names the frame at fault, as tf2's exceptions do.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum LookupError {
    /// No transform ever received for this frame (nor is it anyone's parent).
    #[error("frame {0:?} does not exist in the TF tree")]
    UnknownFrame(String),
    /// Both frames exist but in trees that do not connect.
    #[error("frames {from:?} and {to:?} are not connected in the TF tree")]
    NotConnected {
        /// The source frame.
        from: String,
        /// The target frame.
        to: String,
    },
    /// The time asked is outside what the buffer holds for a frame of the chain.
    #[error(
        "lookup of frame {frame:?} at t = {requested} ns would extrapolate: known from {earliest} to {latest} ns"
    )]
    Extrapolation {
        /// The frame whose transform to its parent is missing at that time.
        frame: String,
        /// The time asked.
        requested: Nanos,
        /// The oldest stamp held for that frame.
        earliest: Nanos,
        /// The newest.
        latest: Nanos,
    },
    /// The parent links loop.
    #[error("the TF tree loops at frame {0:?}")]
    Loop(String),
}

/// One frame's transforms to its parent.
#[derive(Clone, Debug)]
enum Links {
    /// `/tf_static`: valid at every time.
    Static {
        parent: String,
        pose: Isometry3<f64>,
    },
    /// `/tf`: by increasing stamp.
    Dynamic(VecDeque<(Nanos, String, Isometry3<f64>)>),
}

/// The buffer (see the module docs).
#[derive(Clone, Debug)]
pub struct TfBuffer {
    cache: Nanos,
    frames: HashMap<String, Links>,
}

impl TfBuffer {
    /// A buffer keeping `cache_seconds` of each dynamic frame's history (tf2: 10 s).
    pub fn new(cache_seconds: f64) -> Self {
        Self {
            cache: (cache_seconds.max(0.0) * 1e9) as Nanos,
            frames: HashMap::new(),
        }
    }

    /// Transforms held for dynamic frames (for tests and diagnostics).
    pub fn dynamic_len(&self) -> usize {
        self.frames
            .values()
            .map(|l| match l {
                Links::Dynamic(v) => v.len(),
                Links::Static { .. } => 0,
            })
            .sum()
    }

    /// Stores `t` (from `/tf_static` if `is_static`). A dynamic transform older than the
    /// newest held by more than the cache is dropped, as are those it makes too old.
    pub fn insert(&mut self, t: &StampedTransform, is_static: bool) -> Result<(), InsertError> {
        for id in [&t.parent, &t.child] {
            if id.is_empty() || id.starts_with('/') {
                return Err(InsertError::InvalidFrameId(id.clone()));
            }
        }
        if t.parent == t.child {
            return Err(InsertError::SelfParent(t.child.clone()));
        }
        let pose = isometry(t).ok_or_else(|| InsertError::InvalidTransform {
            parent: t.parent.clone(),
            child: t.child.clone(),
        })?;
        if is_static {
            let parent = t.parent.clone();
            self.frames
                .insert(t.child.clone(), Links::Static { parent, pose });
            return Ok(());
        }
        let entry = self
            .frames
            .entry(t.child.clone())
            .or_insert_with(|| Links::Dynamic(VecDeque::new()));
        if let Links::Static { .. } = entry {
            // A frame published on /tf after /tf_static becomes dynamic, as in tf2.
            *entry = Links::Dynamic(VecDeque::new());
        }
        let Links::Dynamic(history) = entry else {
            return Ok(());
        };
        let newest = history.back().map_or(t.stamp, |b| b.0.max(t.stamp));
        if t.stamp < newest.saturating_sub(self.cache) {
            return Ok(());
        }
        let at = history.partition_point(|e| e.0 < t.stamp);
        match history.get_mut(at) {
            // The same stamp again replaces the transform (tf2 keeps the first and warns;
            // keeping the newest serves a publisher that corrects itself).
            Some(e) if e.0 == t.stamp => *e = (t.stamp, t.parent.clone(), pose),
            _ => history.insert(at, (t.stamp, t.parent.clone(), pose)),
        }
        while history
            .front()
            .is_some_and(|e| e.0 < newest.saturating_sub(self.cache))
        {
            history.pop_front();
        }
        Ok(())
    }

    /// The transform taking coordinates in `source` to coordinates in `target` (tf2's
    /// `lookupTransform(target, source, time)`): the pose of `source` in `target`. `time`
    /// `None`: the latest time at which every link of the chain is known.
    pub fn lookup(
        &self,
        target: &str,
        source: &str,
        time: Option<Nanos>,
    ) -> Result<Isometry3<f64>, LookupError> {
        for f in [target, source] {
            if !self.exists(f) {
                return Err(LookupError::UnknownFrame(f.to_string()));
            }
        }
        if target == source {
            return Ok(Isometry3::identity());
        }
        let time = match time {
            Some(t) => Some(t),
            None => self.latest_common_time(target, source)?,
        };
        let up_source = self.chain(source, time)?;
        let up_target = self.chain(target, time)?;
        // The frames from each end up to its root; the lowest common ancestor is the first
        // frame above the source that is also above the target.
        let above = |start: &'_ str, chain: &'_ [(String, Isometry3<f64>)]| -> Vec<String> {
            std::iter::once(start.to_string())
                .chain(chain.iter().map(|(p, _)| p.clone()))
                .collect()
        };
        let (s_frames, t_frames) = (above(source, &up_source), above(target, &up_target));
        let Some((i, j)) = s_frames
            .iter()
            .enumerate()
            .find_map(|(i, f)| t_frames.iter().position(|g| g == f).map(|j| (i, j)))
        else {
            return Err(LookupError::NotConnected {
                from: source.to_string(),
                to: target.to_string(),
            });
        };
        let up_to = |chain: &[(String, Isometry3<f64>)], n: usize| {
            chain[..n]
                .iter()
                .fold(Isometry3::identity(), |acc, (_, pose)| pose * acc)
        };
        Ok(up_to(&up_target, j).inverse() * up_to(&up_source, i))
    }

    /// The transform at the latest time every link of the chain is known (tf2's time 0),
    /// with that time (`None`: the chain is static, valid at every time).
    pub fn lookup_latest(
        &self,
        target: &str,
        source: &str,
    ) -> Result<(Option<Nanos>, Isometry3<f64>), LookupError> {
        for f in [target, source] {
            if !self.exists(f) {
                return Err(LookupError::UnknownFrame(f.to_string()));
            }
        }
        let time = self.latest_common_time(target, source)?;
        Ok((time, self.lookup(target, source, time)?))
    }

    fn exists(&self, frame: &str) -> bool {
        self.frames.contains_key(frame)
            || self.frames.values().any(|l| match l {
                Links::Static { parent, .. } => parent == frame,
                Links::Dynamic(h) => h.iter().any(|e| e.1 == frame),
            })
    }

    /// The links from `frame` up to its root at `time` (`None`: static links only, or any
    /// time for a tree without dynamic links): (parent, pose of the child in the parent).
    fn chain(
        &self,
        frame: &str,
        time: Option<Nanos>,
    ) -> Result<Vec<(String, Isometry3<f64>)>, LookupError> {
        let mut out = Vec::new();
        let mut current = frame.to_string();
        while let Some(links) = self.frames.get(&current) {
            if out.len() >= MAX_GRAPH_DEPTH {
                return Err(LookupError::Loop(current));
            }
            let (parent, pose) = match links {
                Links::Static { parent, pose } => (parent.clone(), *pose),
                Links::Dynamic(h) => at_time(&current, h, time)?,
            };
            out.push((parent.clone(), pose));
            current = parent;
        }
        Ok(out)
    }

    /// tf2's time 0: the newest stamp every dynamic link between the two frames has (`None`
    /// when the chain is static).
    fn latest_common_time(&self, target: &str, source: &str) -> Result<Option<Nanos>, LookupError> {
        let mut latest: Option<Nanos> = None;
        for start in [target, source] {
            let mut current = start.to_string();
            let mut depth = 0;
            while let Some(links) = self.frames.get(&current) {
                depth += 1;
                if depth > MAX_GRAPH_DEPTH {
                    return Err(LookupError::Loop(current));
                }
                current = match links {
                    Links::Static { parent, .. } => parent.clone(),
                    Links::Dynamic(h) => {
                        let Some((stamp, parent, _)) = h.back() else {
                            break;
                        };
                        latest = Some(latest.map_or(*stamp, |l| l.min(*stamp)));
                        parent.clone()
                    }
                };
            }
        }
        Ok(latest)
    }
}

/// A dynamic frame's transform at `time`, interpolated between the two stamps around it.
fn at_time(
    frame: &str,
    h: &VecDeque<(Nanos, String, Isometry3<f64>)>,
    time: Option<Nanos>,
) -> Result<(String, Isometry3<f64>), LookupError> {
    let (first, last) = match (h.front(), h.back()) {
        (Some(f), Some(l)) => (f, l),
        _ => {
            return Err(LookupError::UnknownFrame(frame.to_string()));
        }
    };
    let Some(t) = time else {
        return Ok((last.1.clone(), last.2));
    };
    if t < first.0 || t > last.0 {
        return Err(LookupError::Extrapolation {
            frame: frame.to_string(),
            requested: t,
            earliest: first.0,
            latest: last.0,
        });
    }
    let i = h.partition_point(|e| e.0 < t);
    let after = &h[i];
    if after.0 == t || i == 0 {
        return Ok((after.1.clone(), after.2));
    }
    let before = &h[i - 1];
    if before.1 != after.1 {
        // Re-parented between the two stamps: no interpolation across parents (tf2).
        return Ok((before.1.clone(), before.2));
    }
    let s = (t - before.0) as f64 / (after.0 - before.0) as f64;
    let translation = before
        .2
        .translation
        .vector
        .lerp(&after.2.translation.vector, s);
    let rotation = before.2.rotation.slerp(&after.2.rotation, s);
    Ok((
        before.1.clone(),
        Isometry3::from_parts(Translation3::from(translation), rotation),
    ))
}

/// The transform's isometry, its quaternion normalised; `None` when it is not finite or the
/// quaternion's norm is off by more than [`QUATERNION_NORM_TOLERANCE`].
fn isometry(t: &StampedTransform) -> Option<Isometry3<f64>> {
    let [x, y, z, w] = t.rotation;
    let q = Quaternion::new(w, x, y, z);
    let finite = t
        .translation
        .iter()
        .chain(&t.rotation)
        .all(|v| v.is_finite());
    if !finite || (q.norm() - 1.0).abs() > QUATERNION_NORM_TOLERANCE {
        return None;
    }
    let translation = Vector3::from(t.translation);
    Some(Isometry3::from_parts(
        Translation3::from(translation),
        UnitQuaternion::from_quaternion(q),
    ))
}

/// The target `pose` (stamped in its frame) in frame `base` at its stamp (stamp zero: the
/// latest transforms, tf2's time 0), its header's frame then `base`.
pub fn pose_in_frame(
    buffer: &TfBuffer,
    base: &str,
    pose: &crate::messages::PoseStamped,
) -> Result<crate::messages::PoseStamped, LookupError> {
    let stamp = &pose.header.stamp;
    let time = (stamp.sec != 0 || stamp.nanosec != 0)
        .then(|| i64::from(stamp.sec) * 1_000_000_000 + i64::from(stamp.nanosec));
    let t = buffer.lookup(base, &pose.header.frame_id, time)?;
    let p = &pose.pose.position;
    let q = &pose.pose.orientation;
    let norm = Quaternion::new(q.w, q.x, q.y, q.z).norm();
    if !(norm.is_finite() && norm > 1e-9 && [p.x, p.y, p.z].iter().all(|v| v.is_finite())) {
        // Left as it is for the target's own checks to refuse (non-finite, not a rotation).
        let mut out = pose.clone();
        out.header.frame_id = base.to_string();
        return Ok(out);
    }
    let position = t * nalgebra::Point3::new(p.x, p.y, p.z);
    let rotation = t.rotation * UnitQuaternion::new_normalize(Quaternion::new(q.w, q.x, q.y, q.z));
    let mut out = pose.clone();
    out.header.frame_id = base.to_string();
    out.pose.position = crate::messages::Point {
        x: position.x,
        y: position.y,
        z: position.z,
    };
    let r = rotation.quaternion();
    out.pose.orientation = crate::messages::Quaternion {
        x: r.i,
        y: r.j,
        z: r.k,
        w: r.w,
    };
    Ok(out)
}

/// A `/tf` or `/tf_static` transform as the buffer takes it.
pub fn from_message(t: &crate::messages::TransformStamped) -> StampedTransform {
    let (tr, r) = (&t.transform.translation, &t.transform.rotation);
    StampedTransform {
        parent: t.header.frame_id.clone(),
        child: t.child_frame_id.clone(),
        stamp: i64::from(t.header.stamp.sec) * 1_000_000_000 + i64::from(t.header.stamp.nanosec),
        translation: [tr.x, tr.y, tr.z],
        rotation: [r.x, r.y, r.z, r.w],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    fn tf(parent: &str, child: &str, stamp: Nanos, xyz: [f64; 3], yaw: f64) -> StampedTransform {
        StampedTransform {
            parent: parent.into(),
            child: child.into(),
            stamp,
            translation: xyz,
            rotation: [0.0, 0.0, (yaw / 2.0).sin(), (yaw / 2.0).cos()],
        }
    }

    const S: Nanos = 1_000_000_000;

    fn point(iso: &Isometry3<f64>, p: [f64; 3]) -> [f64; 3] {
        let q = iso * nalgebra::Point3::from(p);
        [q.x, q.y, q.z]
    }

    fn close(a: [f64; 3], b: [f64; 3]) -> bool {
        a.iter().zip(&b).all(|(x, y)| (x - y).abs() < 1e-12)
    }

    #[test]
    fn static_chains_compose_both_ways() {
        let mut b = TfBuffer::new(10.0);
        // world → base: 1 m along x, turned 90° about z; base → tip: 0.5 m along x.
        b.insert(&tf("world", "base", 0, [1.0, 0.0, 0.0], FRAC_PI_2), true)
            .unwrap();
        b.insert(&tf("base", "tip", 0, [0.5, 0.0, 0.0], 0.0), true)
            .unwrap();
        // The tip's origin in world: base's x axis is world's y.
        let t = b.lookup("world", "tip", None).unwrap();
        assert!(close(point(&t, [0.0; 3]), [1.0, 0.5, 0.0]));
        // And back: world's origin seen from the tip.
        let back = b.lookup("tip", "world", Some(5 * S)).unwrap();
        assert!(close(point(&back, [1.0, 0.5, 0.0]), [0.0; 3]));
        // Siblings through their common parent.
        b.insert(&tf("base", "other", 0, [0.0, 2.0, 0.0], 0.0), true)
            .unwrap();
        let t = b.lookup("other", "tip", None).unwrap();
        assert!(close(point(&t, [0.0; 3]), [0.5, -2.0, 0.0]));
        assert_eq!(b.lookup("tip", "tip", None).unwrap(), Isometry3::identity());
    }

    #[test]
    fn dynamic_frames_interpolate_between_stamps_and_refuse_to_extrapolate() {
        let mut b = TfBuffer::new(10.0);
        b.insert(&tf("world", "gripper", S, [0.0, 0.0, 0.0], 0.0), false)
            .unwrap();
        b.insert(
            &tf("world", "gripper", 2 * S, [1.0, 0.0, 0.0], FRAC_PI_2),
            false,
        )
        .unwrap();
        let mid = b.lookup("world", "gripper", Some(S + S / 2)).unwrap();
        assert!(close(point(&mid, [0.0; 3]), [0.5, 0.0, 0.0]));
        let yaw = mid.rotation.euler_angles().2;
        assert!(
            (yaw - FRAC_PI_2 / 2.0).abs() < 1e-12,
            "slerp halfway: {yaw}"
        );
        // Exactly at a stamp, and the latest.
        let end = b.lookup("world", "gripper", Some(2 * S)).unwrap();
        assert!(close(point(&end, [0.0; 3]), [1.0, 0.0, 0.0]));
        assert_eq!(b.lookup("world", "gripper", None).unwrap(), end);
        for t in [S - 1, 2 * S + 1] {
            let e = b.lookup("world", "gripper", Some(t)).unwrap_err();
            assert!(
                matches!(&e, LookupError::Extrapolation { frame, requested, earliest, latest }
                    if frame == "gripper" && *requested == t && *earliest == S && *latest == 2 * S),
                "{e}"
            );
            assert!(e.to_string().contains("gripper"));
        }
    }

    #[test]
    fn the_latest_common_time_is_the_oldest_newest_link() {
        let mut b = TfBuffer::new(10.0);
        // world → base at 1 and 3 s, base → tip at 1 and 2 s: time 0 means 2 s.
        for (stamp, x) in [(S, 0.0), (3 * S, 2.0)] {
            b.insert(&tf("world", "base", stamp, [x, 0.0, 0.0], 0.0), false)
                .unwrap();
        }
        for (stamp, y) in [(S, 0.0), (2 * S, 1.0)] {
            b.insert(&tf("base", "tip", stamp, [0.0, y, 0.0], 0.0), false)
                .unwrap();
        }
        let t = b.lookup("world", "tip", None).unwrap();
        assert!(close(point(&t, [0.0; 3]), [1.0, 1.0, 0.0]));
    }

    #[test]
    fn unknown_and_disconnected_frames_are_named() {
        let mut b = TfBuffer::new(10.0);
        b.insert(&tf("world", "base", 0, [0.0; 3], 0.0), true)
            .unwrap();
        b.insert(&tf("map", "robot", 0, [0.0; 3], 0.0), true)
            .unwrap();
        let e = b.lookup("world", "camera", None).unwrap_err();
        assert_eq!(e, LookupError::UnknownFrame("camera".into()));
        assert!(e.to_string().contains("camera"));
        let e = b.lookup("base", "robot", None).unwrap_err();
        assert!(matches!(e, LookupError::NotConnected { .. }), "{e}");
        assert!(e.to_string().contains("robot") && e.to_string().contains("base"));
        // A parent that is only a parent exists.
        assert!(b.lookup("map", "robot", None).is_ok());
    }

    #[test]
    fn invalid_transforms_are_refused() {
        let mut b = TfBuffer::new(10.0);
        let bad_ids = [("", "a"), ("/world", "a"), ("world", "/a")];
        for (p, c) in bad_ids {
            let e = b.insert(&tf(p, c, 0, [0.0; 3], 0.0), false).unwrap_err();
            assert!(matches!(e, InsertError::InvalidFrameId(_)), "{e}");
        }
        let e = b
            .insert(&tf("a", "a", 0, [0.0; 3], 0.0), false)
            .unwrap_err();
        assert_eq!(e, InsertError::SelfParent("a".into()));
        let mut nan = tf("w", "a", 0, [f64::NAN, 0.0, 0.0], 0.0);
        assert!(b.insert(&nan, false).is_err());
        nan.translation = [0.0; 3];
        nan.rotation = [0.0, 0.0, 0.0, 0.0];
        assert!(b.insert(&nan, false).is_err());
        // Slightly off unit norm: normalised, as tf2 does.
        nan.rotation = [0.0, 0.0, 0.0, 1.005];
        b.insert(&nan, false).unwrap();
        let t = b.lookup("w", "a", None).unwrap();
        assert!((t.rotation.quaternion().norm() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn a_target_pose_is_expressed_in_the_base_frame() {
        use crate::messages::{Header, Point, Pose, PoseStamped, Quaternion as Q, Time};
        let mut b = TfBuffer::new(10.0);
        // world → rod_base: 1 m along world x, turned 90° (rod_base x = world y).
        b.insert(
            &tf("world", "rod_base", 0, [1.0, 0.0, 0.0], FRAC_PI_2),
            true,
        )
        .unwrap();
        let yaw = 0.3f64;
        let target = PoseStamped {
            header: Header {
                stamp: Time { sec: 5, nanosec: 0 },
                frame_id: "world".into(),
            },
            pose: Pose {
                position: Point {
                    x: 1.0,
                    y: 0.6,
                    z: 0.0,
                },
                orientation: Q {
                    x: 0.0,
                    y: 0.0,
                    z: (yaw / 2.0).sin(),
                    w: (yaw / 2.0).cos(),
                },
            },
        };
        let t = pose_in_frame(&b, "rod_base", &target).unwrap();
        assert_eq!(t.header.frame_id, "rod_base");
        assert_eq!(t.header.stamp, target.header.stamp);
        let p = &t.pose.position;
        assert!(
            (p.x - 0.6).abs() < 1e-12 && p.y.abs() < 1e-12 && p.z.abs() < 1e-12,
            "{p:?}"
        );
        let o = &t.pose.orientation;
        let got = 2.0 * o.z.atan2(o.w);
        assert!((got - (yaw - FRAC_PI_2)).abs() < 1e-12, "{got}");
        // An unknown frame names itself.
        let mut lost = target.clone();
        lost.header.frame_id = "camera".into();
        let e = pose_in_frame(&b, "rod_base", &lost).unwrap_err();
        assert!(e.to_string().contains("camera"));
    }

    #[test]
    fn the_cache_bounds_the_history_and_loops_are_caught() {
        let mut b = TfBuffer::new(10.0);
        // 100 s at 1 kHz: only the last 10 s (10,001 stamps) are kept.
        for k in 0..100_000i64 {
            b.insert(
                &tf("world", "g", k * S / 1000, [k as f64, 0.0, 0.0], 0.0),
                false,
            )
            .unwrap();
        }
        assert_eq!(b.dynamic_len(), 10_001);
        assert!(b.lookup("world", "g", Some(50 * S)).is_err());
        // A transform older than the cache is dropped, not stored.
        b.insert(&tf("world", "g", 0, [0.0; 3], 0.0), false)
            .unwrap();
        assert_eq!(b.dynamic_len(), 10_001);
        // a → b → a.
        let mut l = TfBuffer::new(10.0);
        l.insert(&tf("a", "b", 0, [0.0; 3], 0.0), true).unwrap();
        l.insert(&tf("b", "a", 0, [0.0; 3], 0.0), true).unwrap();
        l.insert(&tf("b", "c", 0, [0.0; 3], 0.0), true).unwrap();
        assert!(matches!(
            l.lookup("c", "x", None),
            Err(LookupError::UnknownFrame(_))
        ));
        l.insert(&tf("q", "x", 0, [0.0; 3], 0.0), true).unwrap();
        assert!(matches!(
            l.lookup("c", "x", None),
            Err(LookupError::Loop(_))
        ));
    }
}
