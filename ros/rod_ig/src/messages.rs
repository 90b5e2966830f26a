//! Serde mirrors of the ROS 2 message types the node exchanges.
//!
//! ros2-client ships no message packages, so the standard types are written by hand here.
//! CDR has no field names or tags: the field order (and types) of each struct must match its
//! `.msg` definition exactly. `tests/fixtures/cdr/*.hex` hold the bytes rclpy's serializer
//! produces for the same values; the unit tests at the bottom compare them byte for byte.

use ros2_client::{Message, MessageTypeName, ServiceTypeName};
use serde::{Deserialize, Serialize};

/// `builtin_interfaces/msg/Time`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Time {
    /// Seconds.
    pub sec: i32,
    /// Nanoseconds, in [0, 1e9).
    pub nanosec: u32,
}

/// `builtin_interfaces/msg/Duration`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Duration {
    /// Seconds.
    pub sec: i32,
    /// Nanoseconds, in [0, 1e9).
    pub nanosec: u32,
}

/// `std_msgs/msg/Header`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Header {
    /// Time stamp.
    pub stamp: Time,
    /// Coordinate frame.
    pub frame_id: String,
}

/// `std_msgs/msg/ColorRGBA`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ColorRgba {
    /// Red, [0, 1].
    pub r: f32,
    /// Green, [0, 1].
    pub g: f32,
    /// Blue, [0, 1].
    pub b: f32,
    /// Opacity, [0, 1].
    pub a: f32,
}

/// `geometry_msgs/msg/Point`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Point {
    /// x (m).
    pub x: f64,
    /// y (m).
    pub y: f64,
    /// z (m).
    pub z: f64,
}

/// `geometry_msgs/msg/Vector3`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Vector3 {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
}

/// `geometry_msgs/msg/Transform`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Transform {
    /// Translation (m).
    pub translation: Vector3,
    /// Rotation.
    pub rotation: Quaternion,
}

/// `geometry_msgs/msg/TransformStamped`: the pose of `child_frame_id` in `header.frame_id`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TransformStamped {
    /// Stamp and parent frame.
    pub header: Header,
    /// Child frame.
    pub child_frame_id: String,
    /// The child's pose in the parent.
    pub transform: Transform,
}

/// `tf2_msgs/msg/TFMessage`, what `/tf` and `/tf_static` carry.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TfMessage {
    /// The transforms.
    pub transforms: Vec<TransformStamped>,
}

/// `geometry_msgs/msg/Quaternion` (x, y, z, w order on the wire).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Quaternion {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
    /// w.
    pub w: f64,
}

impl Default for Quaternion {
    /// The identity rotation, as in ROS.
    fn default() -> Self {
        Self {
            x: 0.0,
            y: 0.0,
            z: 0.0,
            w: 1.0,
        }
    }
}

/// `geometry_msgs/msg/Pose`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    /// Position (m).
    pub position: Point,
    /// Orientation.
    pub orientation: Quaternion,
}

/// `geometry_msgs/msg/PoseStamped`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PoseStamped {
    /// Stamp and frame.
    pub header: Header,
    /// The pose.
    pub pose: Pose,
}
impl Message for PoseStamped {}

/// `geometry_msgs/msg/Wrench`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Wrench {
    /// Force (N).
    pub force: Vector3,
    /// Torque (N·m).
    pub torque: Vector3,
}

/// `geometry_msgs/msg/WrenchStamped`: the base wrench for tools that plot or draw wrenches.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct WrenchStamped {
    /// Stamp and frame.
    pub header: Header,
    /// The wrench.
    pub wrench: Wrench,
}
impl Message for WrenchStamped {}
impl Message for TfMessage {}

/// `nav_msgs/msg/Path`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Path {
    /// Stamp and frame of the whole path.
    pub header: Header,
    /// The poses, in order.
    pub poses: Vec<PoseStamped>,
}
impl Message for Path {}

/// `sensor_msgs/msg/CompressedImage` (only nested, empty, in [`Marker`]).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CompressedImage {
    /// Stamp and frame.
    pub header: Header,
    /// Image format.
    pub format: String,
    /// Image bytes.
    pub data: Vec<u8>,
}

/// `visualization_msgs/msg/UVCoordinate`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct UvCoordinate {
    /// u.
    pub u: f32,
    /// v.
    pub v: f32,
}

/// `visualization_msgs/msg/MeshFile`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MeshFile {
    /// File name.
    pub filename: String,
    /// File contents.
    pub data: Vec<u8>,
}

/// `visualization_msgs/msg/Marker` (Kilted definition).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Marker {
    /// Stamp and frame.
    pub header: Header,
    /// Namespace.
    pub ns: String,
    /// Id within the namespace.
    pub id: i32,
    /// Shape type (see the constants).
    #[serde(rename = "type")]
    pub marker_type: i32,
    /// Action (add / delete).
    pub action: i32,
    /// Pose of the marker frame.
    pub pose: Pose,
    /// Scale; for a line strip, `scale.x` is the line width (m).
    pub scale: Vector3,
    /// Colour of the whole marker.
    pub color: ColorRgba,
    /// How long the marker lives (0 = forever).
    pub lifetime: Duration,
    /// Re-transform the marker every frame.
    pub frame_locked: bool,
    /// Points of a line strip.
    pub points: Vec<Point>,
    /// Per-point colours (empty = `color`).
    pub colors: Vec<ColorRgba>,
    /// Texture resource (unused).
    pub texture_resource: String,
    /// Texture (unused).
    pub texture: CompressedImage,
    /// Texture coordinates (unused).
    pub uv_coordinates: Vec<UvCoordinate>,
    /// Text (unused).
    pub text: String,
    /// Mesh resource (unused).
    pub mesh_resource: String,
    /// Mesh file (unused).
    pub mesh_file: MeshFile,
    /// Mesh materials (unused).
    pub mesh_use_embedded_materials: bool,
}
impl Message for Marker {}

impl Marker {
    /// `Marker.LINE_STRIP`.
    pub const LINE_STRIP: i32 = 4;
    /// `Marker.LINE_LIST`.
    pub const LINE_LIST: i32 = 5;
    /// `Marker.ADD`.
    pub const ADD: i32 = 0;
}

/// `rod_ig_msgs/msg/RodSolution` (see `msg/msg/RodSolution.msg` for the meaning of each field).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RodSolution {
    /// Stamp copied from the target, frame = target frame or `base_frame`.
    pub header: Header,
    /// The rod reaches the target.
    pub success: bool,
    /// Why not, or a short summary.
    pub message: String,
    /// Normalised base wrench (a3, a4, a5).
    pub a: [f64; 3],
    /// Stable equilibrium.
    pub stable: bool,
    /// Normalised stability margin.
    pub stability_margin: f64,
    /// Solver iterations.
    pub iterations: u32,
    /// Tip position error (m).
    pub position_error: f64,
    /// Tip orientation error (rad).
    pub orientation_error: f64,
    /// Solver residual (normalised).
    pub residual: f64,
    /// Normalised elastic energy.
    pub elastic_energy: f64,
    /// Elastic energy in joules (NaN without `bending_stiffness`).
    pub elastic_energy_joules: f64,
    /// `base_wrench` is meaningful.
    pub wrench_valid: bool,
    /// Base wrench in N and N·m.
    pub base_wrench: Wrench,
    /// Reached tip pose.
    pub tip: Pose,
    /// Rod length used (m).
    pub rod_length: f64,
    /// Solve wall time (s).
    pub solve_time: f64,
    /// The 3-D solver answered (appended field; `solve_3d` parameter).
    pub spatial: bool,
    /// Normalised 3-D base wrench (a1..a6); zeros for planar answers (appended field).
    pub a_spatial: [f64; 6],
    /// Branch event of the move: "none", "snap", "lost", or "" (not a tracked target).
    pub event: String,
    /// After a snap: where the old branch ended (m); NaN otherwise.
    pub critical_pose: Pose,
    /// Dimensionless weight w of the solve (appended field; 0 without weight).
    pub weight: f64,
    /// Elastic + gravitational energy, normalised (appended field; NaN on failure).
    pub total_energy: f64,
    /// The wrench the rod exerts on the tip gripper (N, N·m), in the tip frame (appended
    /// field; zeros unless `wrench_valid`).
    pub tip_wrench: Wrench,
    /// How the base was held: "clamped" or "pinned" (appended field).
    pub base_condition: String,
    /// How the tip was held: "clamped", "pinned" or "free" (appended field).
    pub tip_condition: String,
    /// The rod's angle at the base (rad): 0 for a clamped base, θ(0) for a pinned one; NaN
    /// when success is false (appended field).
    pub base_angle: f64,
    /// Full turns of the planar rod's tangent along its path (0: loop-free); 0 for the 3-D
    /// solver and on failure (appended field).
    pub turns: u32,
}
impl Message for RodSolution {}

/// Request of `rod_ig_msgs/srv/SolveRod`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SolveRodRequest {
    /// Tip gripper pose in the base frame.
    pub target: PoseStamped,
    /// Start from `initial_guess` rather than the previous solution.
    pub use_initial_guess: bool,
    /// Normalised (a3, a4, a5) start point.
    pub initial_guess: [f64; 3],
    /// Tolerance override (0 = parameter).
    pub tolerance: f64,
    /// Iteration limit override (0 = parameter).
    pub max_iterations: u32,
    /// Method override ("" = parameter).
    pub method: String,
    /// Path poses override (0 = parameter).
    pub path_samples: u32,
    /// Move the held rod (appended field; false = a query without side effects).
    pub move_rod: bool,
}
impl Message for SolveRodRequest {}

/// `geometry_msgs/msg/Point32`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Point32 {
    /// x (m).
    pub x: f32,
    /// y (m).
    pub y: f32,
    /// z (m).
    pub z: f32,
}

/// `geometry_msgs/msg/Polygon`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Polygon {
    /// Vertices in order.
    pub points: Vec<Point32>,
}

/// Request of `rod_ig_msgs/srv/PlanRod`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PlanRodRequest {
    /// Start from the rod the node holds now.
    pub use_current: bool,
    /// Otherwise this rod (normalised a3, a4, a5).
    pub start: [f64; 3],
    /// Goal pose of the tip gripper.
    pub goal: PoseStamped,
    /// Disc centres x (m).
    pub disc_x: Vec<f64>,
    /// Disc centres y (m).
    pub disc_y: Vec<f64>,
    /// Disc radii (m).
    pub disc_radius: Vec<f64>,
    /// Polygons (m).
    pub polygons: Vec<Polygon>,
    /// Budget (ms), 0 = default.
    pub deadline_ms: f64,
}
impl Message for PlanRodRequest {}

/// Response of `rod_ig_msgs/srv/PlanRod`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PlanRodResponse {
    /// A plan was found.
    pub success: bool,
    /// Why not.
    pub reason: String,
    /// Tip poses along the plan (m).
    pub gripper_path: Path,
    /// Rods, 3 numbers each.
    pub rods: Vec<f64>,
    /// Smallest stability margin along the plan.
    pub min_margin: f64,
}
impl Message for PlanRodResponse {}

/// Response of `rod_ig_msgs/srv/SolveRod`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SolveRodResponse {
    /// The solution (success = false with a reason on bad input).
    pub solution: RodSolution,
    /// The shape; no poses unless `solution.success`.
    pub path: Path,
}
impl Message for SolveRodResponse {}

/// `diagnostic_msgs/msg/KeyValue`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct KeyValue {
    /// What the value is.
    pub key: String,
    /// The value, as text.
    pub value: String,
}

/// `diagnostic_msgs/msg/DiagnosticStatus`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct DiagnosticStatus {
    /// OK = 0, WARN = 1, ERROR = 2, STALE = 3.
    pub level: u8,
    /// What is reported on (`"<node>: <task>"`, as diagnostic_updater names it).
    pub name: String,
    /// A human-readable summary.
    pub message: String,
    /// The hardware it concerns (empty for software).
    pub hardware_id: String,
    /// The figures.
    pub values: Vec<KeyValue>,
}

/// `diagnostic_msgs/msg/DiagnosticArray`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct DiagnosticArray {
    /// Stamp of the report.
    pub header: Header,
    /// One status per reported task.
    pub status: Vec<DiagnosticStatus>,
}
impl Message for DiagnosticArray {}

/// DDS type names of the topics and the service.
pub mod type_names {
    use super::*;

    /// `tf2_msgs/msg/TFMessage`.
    pub fn tf_message() -> MessageTypeName {
        MessageTypeName::new("tf2_msgs", "TFMessage")
    }
    /// `geometry_msgs/msg/PoseStamped`.
    pub fn pose_stamped() -> MessageTypeName {
        MessageTypeName::new("geometry_msgs", "PoseStamped")
    }
    /// `nav_msgs/msg/Path`.
    pub fn path() -> MessageTypeName {
        MessageTypeName::new("nav_msgs", "Path")
    }
    /// `geometry_msgs/msg/WrenchStamped`.
    pub fn wrench_stamped() -> MessageTypeName {
        MessageTypeName::new("geometry_msgs", "WrenchStamped")
    }
    /// `visualization_msgs/msg/Marker`.
    pub fn marker() -> MessageTypeName {
        MessageTypeName::new("visualization_msgs", "Marker")
    }
    /// `rod_ig_msgs/msg/RodSolution`.
    pub fn rod_solution() -> MessageTypeName {
        MessageTypeName::new("rod_ig_msgs", "RodSolution")
    }
    /// `diagnostic_msgs/msg/DiagnosticArray`.
    pub fn diagnostic_array() -> MessageTypeName {
        MessageTypeName::new("diagnostic_msgs", "DiagnosticArray")
    }
    /// `rod_ig_msgs/srv/SolveRod`.
    pub fn solve_rod() -> ServiceTypeName {
        ServiceTypeName::new("rod_ig_msgs", "SolveRod")
    }
    /// `rod_ig_msgs/srv/PlanRod`.
    pub fn plan_rod() -> ServiceTypeName {
        ServiceTypeName::new("rod_ig_msgs", "PlanRod")
    }
}

#[cfg(test)]
pub(crate) mod tests {
    //! Byte-exact CDR checks against rclpy (fixtures from `tests/gen_cdr_fixtures.py`).
    use super::*;
    use byteorder::LittleEndian;
    use std::path::PathBuf;

    /// Fields (type, name) of a ROS interface definition, in order: comments, blank lines
    /// and constants skipped, `---` separating the parts of a service.
    fn interface_fields(text: &str) -> Vec<Vec<(String, String)>> {
        let mut parts = vec![Vec::new()];
        for line in text.lines() {
            let line = line.split('#').next().unwrap_or("").trim();
            if line == "---" {
                parts.push(Vec::new());
                continue;
            }
            let mut words = line.split_whitespace();
            if let (Some(ty), Some(name)) = (words.next(), words.next()) {
                if !name.contains('=') && !words.any(|w| w.starts_with('=')) {
                    parts
                        .last_mut()
                        .unwrap()
                        .push((ty.to_string(), name.to_string()));
                }
            }
        }
        parts
    }

    /// The hand-written type has the definition's fields, in its order, each of a matching
    /// kind (bool, number, string, fixed or unbounded array, nested message).
    fn check_matches_definition<T: Serialize>(value: &T, fields: &[(String, String)], what: &str) {
        let json = serde_json::to_value(value).unwrap();
        let obj = json.as_object().unwrap();
        let names: Vec<&str> = obj.keys().map(String::as_str).collect();
        let want: Vec<&str> = fields.iter().map(|(_, n)| n.as_str()).collect();
        assert_eq!(
            names, want,
            "{what}: fields differ from its definition in msg/"
        );
        for (ty, name) in fields {
            let v = &obj[name.as_str()];
            let (base, dims) = match ty.find('[') {
                Some(i) => (&ty[..i], Some(ty[i + 1..].trim_end_matches(']'))),
                None => (ty.as_str(), None),
            };
            let ok = match dims {
                Some(n) if n.parse::<usize>().is_ok() => {
                    v.as_array().map(|a| a.len().to_string()).as_deref() == Some(n)
                }
                Some(_) => v.is_array(), // unbounded or bounded (<=N)
                None => match base {
                    "bool" => v.is_boolean(),
                    "string" => v.is_string(),
                    "float32" | "float64" | "int8" | "uint8" | "int16" | "uint16" | "int32"
                    | "uint32" | "int64" | "uint64" | "byte" | "char" => v.is_number(),
                    _ => v.is_object(), // a nested message
                },
            };
            assert!(ok, "{what}.{name}: {v} is not a {ty}");
        }
    }

    #[test]
    fn hand_written_messages_match_their_definitions() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../msg");
        let read = |p: &str| std::fs::read_to_string(root.join(p)).unwrap();
        let msg = interface_fields(&read("msg/RodSolution.msg"));
        assert_eq!(msg.len(), 1);
        check_matches_definition(&RodSolution::default(), &msg[0], "RodSolution");
        let srv = interface_fields(&read("srv/SolveRod.srv"));
        assert_eq!(srv.len(), 2, "SolveRod.srv: request --- response");
        check_matches_definition(&SolveRodRequest::default(), &srv[0], "SolveRod request");
        check_matches_definition(&SolveRodResponse::default(), &srv[1], "SolveRod response");
        let plan = interface_fields(&read("srv/PlanRod.srv"));
        assert_eq!(plan.len(), 2, "PlanRod.srv: request --- response");
        check_matches_definition(&PlanRodRequest::default(), &plan[0], "PlanRod request");
        check_matches_definition(&PlanRodResponse::default(), &plan[1], "PlanRod response");
        // The check itself catches a drift: a field renamed, dropped or retyped.
        let mut drifted = msg[0].clone();
        drifted[1].1 = "succeeded".into();
        let renamed = std::panic::catch_unwind(|| {
            check_matches_definition(&RodSolution::default(), &drifted, "drifted")
        });
        assert!(renamed.is_err());
        let mut retyped = msg[0].clone();
        retyped[3].0 = "float64[6]".into();
        let retyped = std::panic::catch_unwind(|| {
            check_matches_definition(&RodSolution::default(), &retyped, "retyped")
        });
        assert!(retyped.is_err());
    }

    /// Reads `tests/fixtures/cdr/<name>.hex` and strips the 4-byte encapsulation header
    /// (00 01 00 00 = CDR little endian) that rclpy's `serialize_message` prepends.
    /// The bytes of a CDR fixture written by rclpy (tests/fixtures).
    pub(crate) fn fixture(name: &str) -> Vec<u8> {
        let path: PathBuf = [
            env!("CARGO_MANIFEST_DIR"),
            "..",
            "..",
            "tests",
            "fixtures",
            "cdr",
            name,
        ]
        .iter()
        .collect();
        let text = std::fs::read_to_string(&path)
            .unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
        let hex: String = text.split_whitespace().collect();
        let bytes: Vec<u8> = (0..hex.len())
            .step_by(2)
            .map(|i| u8::from_str_radix(&hex[i..i + 2], 16).expect("hex fixture"))
            .collect();
        assert_eq!(&bytes[..4], &[0, 1, 0, 0], "{name}: not CDR little endian");
        bytes[4..].to_vec()
    }

    /// CDR payload as ros2-client writes it.
    fn cdr<T: Serialize>(value: &T) -> Vec<u8> {
        ros2_client::dds::rustdds::cdr_encoding::to_vec::<T, LittleEndian>(value)
            .expect("serialize")
    }

    /// Compares, allowing trailing alignment padding (zeros, < 8 bytes) on one side only.
    fn assert_same(ours: &[u8], theirs: &[u8], name: &str) {
        let n = ours.len().min(theirs.len());
        let tail = if ours.len() > n {
            &ours[n..]
        } else {
            &theirs[n..]
        };
        assert!(
            tail.len() < 8 && tail.iter().all(|&b| b == 0),
            "{name}: lengths differ: ours {} rclpy {}",
            ours.len(),
            theirs.len()
        );
        assert_eq!(&ours[..n], &theirs[..n], "{name}: CDR differs from rclpy");
    }

    fn check<T>(value: &T, name: &str)
    where
        T: Serialize + for<'de> Deserialize<'de> + PartialEq + std::fmt::Debug,
    {
        let theirs = fixture(name);
        let ours = cdr(value);
        assert_same(&ours, &theirs, name);
        let (back, _) =
            ros2_client::dds::rustdds::cdr_encoding::from_bytes::<T, LittleEndian>(&theirs)
                .unwrap_or_else(|e| panic!("{name}: deserializing rclpy bytes: {e}"));
        assert_eq!(&back, value, "{name}: round trip from rclpy bytes");
    }

    fn header() -> Header {
        Header {
            stamp: Time {
                sec: 1_700_000_000,
                nanosec: 123_456_789,
            },
            frame_id: "base_gripper".into(),
        }
    }

    /// Pose number `i` of the fixtures (exactly representable values, see the generator).
    fn pose(i: usize) -> Pose {
        let (z, w) = [(0.0, 1.0), (0.6, 0.8), (0.28, 0.96)][i % 3];
        Pose {
            position: Point {
                x: 0.25 + i as f64,
                y: -0.5 * i as f64,
                z: 0.0,
            },
            orientation: Quaternion {
                x: 0.0,
                y: 0.0,
                z,
                w,
            },
        }
    }

    pub(crate) fn sample_pose_stamped() -> PoseStamped {
        PoseStamped {
            header: header(),
            pose: pose(1),
        }
    }

    pub(crate) fn sample_path() -> Path {
        Path {
            header: header(),
            poses: (0..3)
                .map(|i| PoseStamped {
                    header: header(),
                    pose: pose(i),
                })
                .collect(),
        }
    }

    pub(crate) fn sample_marker() -> Marker {
        Marker {
            header: header(),
            ns: "rod".into(),
            id: 7,
            marker_type: Marker::LINE_STRIP,
            action: Marker::ADD,
            pose: Pose::default(),
            scale: Vector3 {
                x: 0.01,
                y: 0.0,
                z: 0.0,
            },
            color: ColorRgba {
                r: 0.1,
                g: 0.8,
                b: 0.2,
                a: 1.0,
            },
            lifetime: Duration { sec: 0, nanosec: 5 },
            frame_locked: true,
            points: vec![
                Point {
                    x: 0.0,
                    y: 0.0,
                    z: 0.0,
                },
                Point {
                    x: 0.5,
                    y: 0.25,
                    z: 0.0,
                },
            ],
            colors: vec![],
            texture_resource: String::new(),
            texture: CompressedImage::default(),
            uv_coordinates: vec![],
            text: String::new(),
            mesh_resource: String::new(),
            mesh_file: MeshFile::default(),
            mesh_use_embedded_materials: false,
        }
    }

    pub(crate) fn sample_rod_solution() -> RodSolution {
        RodSolution {
            header: header(),
            success: true,
            message: "ok".into(),
            a: [1.5, -2.25, 3.125],
            stable: true,
            stability_margin: 0.5,
            iterations: 7,
            position_error: 1e-9,
            orientation_error: 2e-9,
            residual: 3e-10,
            elastic_energy: 4.5,
            elastic_energy_joules: 0.045,
            wrench_valid: true,
            base_wrench: Wrench {
                force: Vector3 {
                    x: 1.0,
                    y: 2.0,
                    z: 0.0,
                },
                torque: Vector3 {
                    x: 0.0,
                    y: 0.0,
                    z: -3.0,
                },
            },
            tip: pose(1),
            rod_length: 0.8,
            solve_time: 0.00025,
            spatial: true,
            a_spatial: [0.5, -0.25, 1.5, -2.25, 3.125, 0.75],
            event: "snap".into(),
            critical_pose: pose(2),
            weight: 15.1,
            total_energy: 3.25,
            tip_wrench: Wrench {
                force: Vector3 {
                    x: -0.5,
                    y: 0.25,
                    z: 0.0,
                },
                torque: Vector3 {
                    x: 0.0,
                    y: 0.0,
                    z: 1.75,
                },
            },
            base_condition: "pinned".into(),
            tip_condition: "free".into(),
            base_angle: -0.5,
            turns: 2,
        }
    }

    pub(crate) fn sample_request() -> SolveRodRequest {
        SolveRodRequest {
            target: sample_pose_stamped(),
            use_initial_guess: true,
            initial_guess: [0.1, 0.2, 0.3],
            tolerance: 1e-8,
            max_iterations: 50,
            method: "newton".into(),
            path_samples: 9,
            move_rod: true,
        }
    }

    pub(crate) fn sample_response() -> SolveRodResponse {
        SolveRodResponse {
            solution: sample_rod_solution(),
            path: sample_path(),
        }
    }

    #[test]
    fn pose_stamped_matches_rclpy() {
        check(&sample_pose_stamped(), "pose_stamped.hex");
    }

    #[test]
    fn path_matches_rclpy() {
        check(&sample_path(), "path.hex");
    }

    #[test]
    fn marker_matches_rclpy() {
        check(&sample_marker(), "marker.hex");
    }

    #[test]
    fn rod_solution_matches_rclpy() {
        check(&sample_rod_solution(), "rod_solution.hex");
    }

    #[test]
    fn solve_rod_request_matches_rclpy() {
        check(&sample_request(), "solve_rod_request.hex");
    }

    #[test]
    fn solve_rod_response_matches_rclpy() {
        check(&sample_response(), "solve_rod_response.hex");
    }
}
