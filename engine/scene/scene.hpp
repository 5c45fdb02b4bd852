#pragma once
/// The scene: everything a run simulates, in SI units, as parsed from a scene file.
/// Absent sections stay empty/inactive so the simulator builds nothing for them.
#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace vb {

using Vec3 = Eigen::Vector3d;

/// Analytic solid voxelised into the model; later shapes override earlier ones.
struct ShapeSpec {
  enum class Kind { Box, Sphere, Ellipsoid, HalfEllipsoid, Hemisphere };
  Kind kind = Kind::Box;
  Vec3 min_m = Vec3::Zero(), max_m = Vec3::Zero();  ///< box corners (m)
  Vec3 center_m = Vec3::Zero();                     ///< sphere/ellipsoid centre (m)
  Vec3 radii_m = Vec3::Zero();                      ///< ellipsoid semi-axes along x, y, z (m)
  double radius_m = 0;                              ///< sphere/hemisphere radius (m)
  Vec3 axis = Vec3::UnitZ();  ///< half shapes keep the side where (p - centre)·axis ≥ 0 (unit)
  std::string label;          ///< tissue name; must name a [materials.X] table
  int line = 0;               ///< scene-file line, for error messages
};

/// Hounsfield-unit class: CT voxels with min ≤ HU < max become `tissue`.
struct HuClass {
  std::string tissue;
  double min_hu = 0, max_hu = 0;
  int line = 0;
};

struct ModelSpec {
  double spacing_m = 0;  ///< lattice spacing (m); for images 0 means the image's largest spacing
  int downsample = 1;    ///< merge downsample³ voxels into one element
  std::vector<ShapeSpec> shapes;

  // CT image models (instead of shapes)
  std::string image_path;   ///< CT as a NIfTI file or a DICOM series folder (resolved path)
  std::string series_uid;   ///< DICOM series to use when the folder holds several
  bool allow_gaps = false;  ///< accept uneven DICOM slice spacing (with a warning)
  std::string labels_path;  ///< label volume (NIfTI) on the CT grid
  std::map<int, std::string> label_table;  ///< label value → tissue name
  std::vector<HuClass> hu_classes;         ///< alternative to a label volume
  std::vector<std::string> keep;           ///< tissues to build (empty: all classified tissues)
  std::optional<std::pair<Vec3, Vec3>> roi_m;  ///< world box (min, max) the model is cropped to
  int line = 0;

  bool from_image() const { return !image_path.empty(); }
};

/// Per-tissue material: linear or biphasic lattice springs, or a hyperelastic law (docs/PHYSICS.md).
struct MaterialSpec {
  std::string name;
  std::string law = "linear";  ///< linear | biphasic | neo-hookean | mooney-rivlin | ogden
  double youngs_modulus_pa = 0;
  double density_kg_m3 = 1000;
  double poisson_ratio = 0.45;         ///< hyperelastic laws: sets κ unless bulk_modulus_pa is given
  double bulk_modulus_pa = 0;          ///< κ (Pa); 0: from the shear modulus and poisson_ratio
  double c10_pa = 0, c01_pa = 0;       ///< Mooney-Rivlin constants (Pa)
  std::vector<double> ogden_mu_pa;     ///< Ogden μ_p (Pa)
  std::vector<double> ogden_alpha;     ///< Ogden α_p
  double cubic = 0;                    ///< biphasic springs: cubic coefficient c3 (dimensionless)
  double critical_strain = 0;          ///< biphasic springs: critical strain εc (dimensionless)
  bool rigid = false;  ///< held in place (bone): no motion, anchors its soft neighbours
  int line = 0;

  /// Whether the law is parametrised by Young's modulus E (the others by c10, or μ and α).
  bool law_takes_E() const { return law == "linear" || law == "biphasic" || law == "neo-hookean"; }
  /// Whether the tissue steps by a hyperelastic law (rigid tissue and springs do not).
  bool hyperelastic() const { return !rigid && law != "linear" && law != "biphasic"; }
};

/// Relaxation: dynamic relaxation for the static answer only (fictitious masses and damping;
/// docs/PHYSICS.md, "Fast equilibrium").
enum class Integrator { SymplecticEuler, Heun, Relaxation };
enum class Precision { Float, Double };

struct SolverSpec {
  Integrator integrator = Integrator::Heun;
  std::optional<double> dt_s;       ///< empty: "auto" (stable step from the stiffest mode)
  double dt_safety = 0.5;           ///< fraction of the stability limit that "auto" uses (relaxation: 0.9)
  Precision precision = Precision::Float;
  double damping_per_s = 0;         ///< global mass-proportional viscous damping γ (1/s): f = -mγv
  double dashpot_ratio = 0.1;       ///< connection dashpot damping ratio ζ: c = 2ζ√(k·m_reduced)
  int check_every = 100;            ///< steps between equilibrium/instability checks
  double hourglass = 0.1;           ///< hourglass-control spring fraction for hyperelastic tissues
};

struct GravitySpec {
  bool active = false;
  Vec3 acceleration_m_s2 = Vec3::Zero();
  std::string posture;  ///< posture name when given by name (supine, prone, ...), else empty
};

struct AnchorSpec {
  enum class Kind { Sphere, HalfSpace, Box };
  std::string name;
  Kind kind = Kind::Sphere;
  Vec3 center_m = Vec3::Zero();
  double radius_m = 0;
  Vec3 rpy_deg = Vec3::Zero();  ///< sphere pose: roll (x), pitch (y), yaw (z) about the centre (deg)
  Vec3 point_m = Vec3::Zero();  ///< half-space: a point on the plane (m)
  Vec3 normal = Vec3::UnitZ();  ///< half-space: elements with (p - point)·normal ≥ 0 are held
  Vec3 min_m = Vec3::Zero(), max_m = Vec3::Zero();  ///< box region (m)
  int line = 0;
};

/// One knot of a recorded indenter trajectory: the indenter's reference point at a time; between
/// knots it moves linearly, before the first and after the last it holds.
struct PathKnot {
  double time_s = 0;
  Vec3 position_m = Vec3::Zero();
};

/// Rigid indenter moved at constant velocity, or along a recorded trajectory. By default it pushes
/// (frictionless) the elements it touches; it can also hold them on its surface (slide: bonded
/// along the normal, free along the surface; stick: moving with it), which gives tension and
/// shear tests. Shapes (docs/SCENE.md, [[indenter]]): a sphere, a plate, a flat-ended cylinder
/// (punch) and a capsule (finger).
struct IndenterSpec {
  enum class Kind { Sphere, Plate, Cylinder, Capsule };
  enum class Contact { Push, Slide, Stick };
  Kind kind = Kind::Sphere;
  Contact contact = Contact::Push;
  double friction = 0;               ///< Coulomb coefficient μ of push contact (0: frictionless)
  /// what the indenter touches (docs/PROBING.md): the surface elements (vertices: a constraint)
  /// or the surface triangles (a penalty force split to each triangle's vertices by the
  /// barycentric weights of the contact point: a point probe between vertices)
  enum class Surface { Vertices, Triangles };
  Surface contact_surface = Surface::Vertices;
  /// triangles: the penalty stiffness k_p as a multiple of the stiffest free element's Gershgorin
  /// row stiffness (engine/sim/triangle_contact.hpp)
  double contact_stiffness = 1;
  double radius_m = 0;               ///< sphere, cylinder, capsule radius (m)
  double length_m = 0;               ///< capsule: length of its axis segment (m)
  /// sphere centre / a point on the plate / centre of the cylinder's flat end / the capsule's tip
  /// centre (the segment's first end) at t = 0 (m)
  Vec3 start_m = Vec3::Zero();
  /// plate: unit normal from the plate into the tissue; cylinder: unit axis from the body
  /// through its flat end (the press direction); capsule: unit direction from the tip along the segment
  Vec3 normal = Vec3::UnitZ();
  Vec3 velocity_m_s = Vec3::Zero();  ///< (m/s)
  double travel_time_s = std::numeric_limits<double>::infinity();  ///< stops moving after this
  std::vector<PathKnot> path;        ///< recorded trajectory (replaces start/velocity); empty: none
  std::string path_file;             ///< the trajectory's CSV (for messages), empty if none
  bool has_start = true;             ///< false: the scene file gave none (the [probe] indenter may omit it)
  int line = 0;
};

/// A line of quasi-static presses ([probe], docs/SCENE.md, docs/PROBING.md): the model first
/// settles (gravity equilibrium), then each press starts from that settled state, moves the
/// indenter in `steps` equal increments to `depth` along `direction`, reaches equilibrium at each
/// and records the reaction force; the presses are spread evenly from `from` to `to`.
struct ProbeSpec {
  bool active = false;
  std::size_t indenter = 0;          ///< which [[indenter]] presses (0-based; the scene key is 1-based)
  Vec3 from_m = Vec3::Zero();        ///< the indenter's reference point for the first press (m)
  Vec3 to_m = Vec3::Zero();          ///< ... and for the last (m)
  int presses = 1;
  Vec3 direction = -Vec3::UnitZ();   ///< unit press direction
  double depth_m = 0;                ///< press depth beyond the zero point (m)
  int steps = 10;                    ///< quasi-static increments per press
  /// zero point of each press: where the indenter first touches the settled surface when moved
  /// from `from`…`to` along `direction` (true), or the given point itself (false)
  bool from_contact = true;
  std::vector<double> at_force_n;    ///< report the press depth at these forces (N)
  int line = 0;
};

/// One knot of a torus inflation schedule: the tube's radii at a time; between knots they change
/// linearly, before the first and after the last they hold.
struct TorusKnot {
  double time_s = 0;
  double minor_radius_m = 0;  ///< tube radius r (m)
  double major_radius_m = 0;  ///< radius R of the tube's centre circle (m); r < R
};

/// Rigid inflatable torus of the immobilisation device ([[device.torus]], docs/SCENE.md): the
/// points within r(t) of the circle of radius R(t) about `axis` through `center`. It pushes the
/// elements it touches (unilateral, frictionless unless `friction` > 0: Coulomb).
struct TorusSpec {
  std::string name;
  Vec3 center_m = Vec3::Zero();
  Vec3 axis = Vec3::UnitZ();         ///< unit
  std::vector<TorusKnot> schedule;   ///< ≥ 1 knots, strictly increasing times ≥ 0
  double friction = 0;               ///< Coulomb coefficient μ (0: frictionless)
  int line = 0;
};

/// What positioning metrics refer to ([positioning], docs/POSITIONING.md). Everything optional.
struct PositioningSpec {
  std::string tumour_tissue;           ///< tissue whose centroid is tracked; empty: "tumour" if present
  std::optional<Vec3> target_m;        ///< planned tumour position (m)
  std::string chest_wall;              ///< anchor standing for the chest wall; empty: the only sphere anchor
  int line = 0;
};

struct TrackSpec {
  std::string name;
  Vec3 point_m = Vec3::Zero();
  int line = 0;
};

struct StopSpec {
  double equilibrium = 1e-6;  ///< relative tolerance (see docs/SCENE.md); 0 disables
  std::int64_t max_steps = 200000;
  double max_time_s = std::numeric_limits<double>::infinity();
};

struct OutputSpec {
  int frames_every = 0;  ///< store displacement frames every N steps in result.h5 (0: none)
  // Image models only: results on the input CT's grid (docs/OUTPUTS.md).
  bool dvf = true;              ///< dvf.nii.gz (forward) and dvf_inverse.nii.gz
  bool warped_ct = true;        ///< warped_ct.nii.gz
  bool warped_ct_dicom = true;  ///< warped_ct_dicom/ series (new UIDs, patient/study copied)
  bool fields = true;           ///< model_labels.nii.gz and per-element fields as NIfTI
  /// surface meshes (rest and deformed .vtp, .stl, .ply) and the lattice (.vtu): docs/OUTPUTS.md
  bool surfaces = false;
};

/// Volume preservation (docs/PHYSICS.md, "Volume preservation"): after every `every` steps the
/// free surface elements are projected so that the volume enclosed by the surface mesh returns to
/// its rest value, and the velocity along the volume gradient is removed.
struct VolumeSpec {
  /// How Heun's predicted stage (ũ, ṽ) meets the constraint: the pressure of the last correction
  /// as a force (no projection of its own), or a projection like the corrected stage's.
  enum class Predictor { Pressure, Projection };
  bool preserve = false;  ///< off unless the scene asks
  int every = 1;          ///< steps between corrections (≥ 1)
  Predictor predictor = Predictor::Pressure;
  int line = 0;
};

/// The unloaded reference state ([reference_state], docs/PHYSICS.md §13): the CT was taken under
/// gravity, so the rest shape is estimated — rest positions that, loaded by the CT posture's
/// gravity, land on the CT — and the run starts from the CT in equilibrium on that rest shape.
struct ReferenceStateSpec {
  bool active = false;
  Vec3 ct_gravity_m_s2 = Vec3::Zero();  ///< gravity when the CT was taken (body frame)
  std::string ct_posture;               ///< its posture name when given by name
  double tolerance_m = 1e-5;            ///< stop when no element lands farther than this from the CT
  int max_iterations = 20;
  int line = 0;
};

/// Reproducibility of a positioning ([reproducibility], docs/POSITIONING.md): the run repeated
/// under random roll/pitch/yaw of the chest-wall anchor, with and without the device.
struct ReproducibilitySpec {
  bool active = false;
  int perturbations = 8;       ///< N perturbed runs per configuration
  double max_angle_deg = 1.0;  ///< each of roll, pitch, yaw uniform in [−θ, θ]
  std::uint64_t seed = 1;      ///< of the angle sequence (the same seed gives the same angles)
  int line = 0;
};

struct Scene {
  ModelSpec model;
  std::map<std::string, MaterialSpec> materials;
  SolverSpec solver;
  GravitySpec gravity;
  std::vector<AnchorSpec> anchors;
  std::vector<IndenterSpec> indenters;
  std::vector<TorusSpec> tori;  ///< [[device.torus]]
  PositioningSpec positioning;
  std::vector<TrackSpec> tracks;
  StopSpec stop;
  OutputSpec output;
  VolumeSpec volume;
  ReferenceStateSpec reference_state;
  ReproducibilitySpec reproducibility;
  ProbeSpec probe;  ///< [probe]: voxbreast probe runs a line of presses
  std::string source_path;  ///< file the scene came from (for messages)
  std::string source_text;  ///< the scene file text, stored with results
};

}  // namespace vb
