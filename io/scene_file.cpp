#include "io/scene_file.hpp"
#include "io/scene_structures.hpp"
#include "io/toml_text.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <string_view>
#include <utility>
#include <vector>

#include "engine/error.hpp"
#include "engine/material/default_materials.hpp"
#include "engine/material/hyperelastic.hpp"
#include "engine/loads/posture.hpp"
#include "io/did_you_mean.hpp"
#include "io/toml_section.hpp"
#include "io/indenter_path_csv.hpp"

namespace vb {
using namespace scene_toml;
namespace {

// ---- the scene's sections -------------------------------------------------------------------

void read_box(const Section& s, Vec3& min, Vec3& max) {
  min = s.required("min", s.vec3("min"));
  max = s.required("max", s.vec3("max"));
  if (!(max.array() > min.array()).all()) s.fail("max", "must exceed 'min' in every component");
}

const NameTable<ShapeSpec::Kind> kShapeKinds = {
    {"box", ShapeSpec::Kind::Box, {"kind", "label", "min", "max"}},
    {"sphere", ShapeSpec::Kind::Sphere, {"kind", "label", "center", "radius"}},
    {"ellipsoid", ShapeSpec::Kind::Ellipsoid, {"kind", "label", "center", "radii"}},
    {"half_ellipsoid",
     ShapeSpec::Kind::HalfEllipsoid,
     {"kind", "label", "center", "radii", "axis"}},
    {"hemisphere", ShapeSpec::Kind::Hemisphere, {"kind", "label", "center", "radius", "axis"}},
};

ShapeSpec read_shape(const Section& s) {
  ShapeSpec shape;
  const Named<ShapeSpec::Kind>& kind = s.kind(kShapeKinds);
  shape.kind = kind.value;
  shape.line = s.line();
  shape.label = s.required("label", s.text("label"));
  // Kinds share keys (centre, radius, ...); the kind's key list says which it has.
  const auto has = [&](std::string_view key) { return contains(kind.keys, key); };
  if (has("min")) read_box(s, shape.min_m, shape.max_m);
  if (has("center")) shape.center_m = s.required("center", s.vec3("center"));
  if (has("radius")) shape.radius_m = s.required("radius", s.positive("radius"));
  if (has("radii")) shape.radii_m = s.required("radii", s.positive_vec3("radii"));
  if (has("axis")) shape.axis = s.direction("axis").value_or(shape.axis);
  return shape;
}

/// `[model.label_table]`: label value (a key, e.g. "3") → tissue name.
std::map<int, std::string> read_label_table(const Section& s) {
  std::map<int, std::string> table;
  for (const std::string& key : s.keys()) {
    char* end = nullptr;
    const long value = std::strtol(key.c_str(), &end, 10);
    if (key.empty() || *end != '\0' || value < 0 || value > 65535) {
      s.fail(key, "label table keys are label values 0..65535", "write e.g. 3 = \"fibroglandular\"");
    }
    table[int(value)] = s.required(key, s.text(key));
  }
  if (table.empty()) s.fail("", "the label table is empty", "map label values to tissue names");
  return table;
}

/// `[model.structure_table]`: ROI name → tissue name.
std::map<std::string, std::string> read_structure_table(const Section& s) {
  std::map<std::string, std::string> table;
  for (const std::string& key : s.keys()) table[key] = s.required(key, s.text(key));
  if (table.empty()) s.fail("", "the structure table is empty", "map ROI names to tissue names");
  return table;
}

/// `model.structures`, `[model.structure_table]` and `model.structure_priority` (path as written).
StructureSpec read_structure_spec(const Section& s) {
  StructureSpec spec;
  spec.path = s.text("structures").value_or("");
  if (const auto table = s.table("structure_table")) spec.table = read_structure_table(*table);
  spec.priority = s.strings("structure_priority").value_or(std::vector<std::string>{});
  return spec;
}

HuClass read_hu_class(const Section& s) {
  s.check_keys({"tissue", "min", "max"});
  HuClass c;
  c.line = s.line();
  c.tissue = s.required("tissue", s.text("tissue"));
  c.min_hu = s.required("min", s.number("min"));
  c.max_hu = s.required("max", s.number("max"));
  if (c.max_hu <= c.min_hu) s.fail("max", "must be greater than min");
  return c;
}

/// model.spacing (m). Above 0.1 m a lattice is coarser than any breast it could model: such a
/// value is millimetres written where metres belong, refused with the conversion.
std::optional<double> read_spacing(const Section& s) {
  const std::optional<double> h = s.positive("spacing");
  if (h && *h > 0.1)
    s.fail("spacing", "must be at most 0.1 (metres), got " + format_number(*h),
           "lengths in a scene are in metres: " + format_number(*h) + " mm is " + format_number(*h * 1e-3));
  return h;
}

/// Image models: a CT (NIfTI file or DICOM folder) classified by a label volume or HU classes.
void read_image_model(const Section& s, ModelSpec& model) {
  model.image_path = *s.text("image");
  model.series_uid = s.text("series").value_or("");
  model.allow_gaps = s.boolean("allow_gaps").value_or(false);
  model.labels_path = s.text("labels").value_or("");
  if (const auto table = s.table("label_table")) model.label_table = read_label_table(*table);
  for (const Section& c : s.tables("hu_class")) model.hu_classes.push_back(read_hu_class(c));
  const StructureSpec structures = read_structure_spec(s);
  const bool by_labels = !model.labels_path.empty(), by_structures = !structures.path.empty();
  if (int(by_labels) + int(by_structures) + int(!model.hu_classes.empty()) != 1) {
    s.fail("image", "an image model needs exactly one of 'labels' (with [model.label_table]), 'structures' (with "
                    "[model.structure_table]) or [[model.hu_class]]");
  }
  if (by_structures && structures.table.empty())
    s.fail("structures", "'structures' needs a [model.structure_table]");
  if (!by_structures && (!structures.table.empty() || !structures.priority.empty()))
    s.fail(structures.table.empty() ? "structure_priority" : "structure_table", "needs 'structures'");
  if (by_labels && model.label_table.empty()) s.fail("labels", "'labels' needs a [model.label_table]");
  if (!by_labels && !model.label_table.empty()) s.fail("label_table", "[model.label_table] needs 'labels'");
  model.keep = s.strings("keep").value_or(std::vector<std::string>{});
  const std::optional<Vec3> lo = s.vec3("roi_min"), hi = s.vec3("roi_max");
  if (lo.has_value() != hi.has_value()) s.fail(lo ? "roi_max" : "roi_min", "roi_min and roi_max go together");
  if (lo) {
    if (!(hi->array() > lo->array()).all()) s.fail("roi_max", "must exceed roi_min in every component");
    model.roi_m = std::make_pair(*lo, *hi);
  }
  model.spacing_m = read_spacing(s).value_or(0.0);
}

ModelSpec read_model(const Section& s) {
  s.check_keys({"spacing", "downsample", "shape", "image", "series", "allow_gaps", "labels", "label_table",
                "hu_class", "keep", "roi_min", "roi_max", "structures", "structure_table", "structure_priority"});
  ModelSpec model;
  model.line = s.line();
  model.downsample = s.integer<int>("downsample", 1).value_or(model.downsample);
  for (const Section& shape : s.tables("shape")) model.shapes.push_back(read_shape(shape));
  if (s.find("image")) {
    if (!model.shapes.empty()) s.fail("image", "a model comes from an image or from shapes, not both");
    read_image_model(s, model);
    return model;
  }
  for (const char* key : {"series", "allow_gaps", "labels", "label_table", "hu_class", "keep", "roi_min", "roi_max",
                          "structures", "structure_table", "structure_priority"}) {
    if (s.find(key)) s.fail(key, "applies to image models only", "add model.image or remove it");
  }
  if (model.shapes.empty()) {
    s.fail("shape", "the model has no shapes", "add [[model.shape]] tables or model.image; see docs/SCENE.md");
  }
  model.spacing_m = s.required("spacing", read_spacing(s));
  return model;
}

void check_law(const Section& s, const std::string& law) {
  const Keys available = {"linear", "biphasic", "neo-hookean", "mooney-rivlin", "ogden"};
  const Keys later = {};
  if (contains(available, law)) return;
  if (contains(later, law)) s.fail("law", "law '" + law + "' is not available in this version", "use " + joined(available));
  s.fail("law", "unknown law '" + law + "'", choice_hint(law, available));
}

/// Keys each law reads; any other law key in the table is a mix-up and an error.
const std::map<std::string, Keys> kLawKeys = {
    {"linear", {"E"}},
    {"biphasic", {"E", "cubic", "critical_strain"}},
    {"neo-hookean", {"E", "nu", "bulk_modulus"}},
    {"mooney-rivlin", {"c10", "c01", "nu", "bulk_modulus"}},
    {"ogden", {"mu", "alpha", "nu", "bulk_modulus"}},
};

/// A tissue with a default (docs/MATERIALS.md) may give only the values it changes.
MaterialSpec read_material(const std::string& name, const Section& s) {
  s.check_keys({"law", "E", "density", "nu", "rigid", "bulk_modulus", "c10", "c01", "mu", "alpha", "cubic",
                "critical_strain"});
  const std::optional<MaterialSpec> fallback = default_material(name);
  MaterialSpec m = fallback.value_or(MaterialSpec{});
  m.name = name;
  m.line = s.line();
  const std::optional<std::string> law = s.text("law");
  if (law) {
    m.law = *law == "neo_hookean" ? "neo-hookean" : *law == "mooney_rivlin" ? "mooney-rivlin" : *law;
    if (m.law == "biphasic_spring") m.law = "biphasic";
    check_law(s, m.law);
  }
  for (const char* key : {"E", "nu", "bulk_modulus", "c10", "c01", "mu", "alpha", "cubic", "critical_strain"}) {
    if (!s.find(key) || contains(kLawKeys.at(m.law), key)) continue;
    if ((m.law == "linear" || m.law == "biphasic") && std::string_view(key) == "nu")
      s.fail(key, m.law + " lattice springs have Poisson ratio 0.25 fixed; 'nu' applies to hyperelastic laws", "remove 'nu'");
    s.fail(key, "'" + std::string(key) + "' does not apply to law '" + m.law + "'", "keys for this law: " + joined(kLawKeys.at(m.law)));
  }
  m.rigid = s.boolean("rigid").value_or(m.rigid);
  const std::optional<double> E = s.positive("E");
  if (m.law_takes_E() && !E && !fallback && !m.rigid) s.fail("E", "missing required key", "'" + name + "' has no default material");
  // Beyond any material, and beyond what float forces (E·h² and its products) can hold.
  constexpr double kStiffestModulus = 1e13;
  if (E && *E > kStiffestModulus)
    s.fail("E", "must be at most " + format_number(kStiffestModulus) + " Pa, got " + format_number(*E),
           "E is in Pa: the stiffest material, diamond, has 1.2e12 Pa; for tissue that does not move, use rigid = true");
  m.youngs_modulus_pa = E.value_or(fallback ? fallback->youngs_modulus_pa : m.rigid ? 1e12 : 0.0);
  if (const std::optional<double> rho = s.positive("density")) {
    // Tissue lies near 1000 kg/m³; below 10 it is g/cm³ (or t/m³) written where kg/m³ belongs.
    if (*rho < 10 || *rho > 30000)
      s.fail("density", "must lie in [10, 30000] kg/m³, got " + format_number(*rho),
             *rho < 10 ? "density is in kg/m³: " + format_number(*rho) + " g/cm³ is " + format_number(*rho * 1e3) + " kg/m³"
                       : "density is in kg/m³ (tissue: 900–1100)");
    m.density_kg_m3 = *rho;
  }
  m.poisson_ratio = s.number("nu").value_or(m.poisson_ratio);
  m.bulk_modulus_pa = s.positive("bulk_modulus").value_or(0.0);
  m.c10_pa = s.number("c10").value_or(0.0);
  m.c01_pa = s.number("c01").value_or(0.0);
  m.ogden_mu_pa = s.numbers("mu").value_or(std::vector<double>{});
  m.ogden_alpha = s.numbers("alpha").value_or(std::vector<double>{});
  if (m.law == "mooney-rivlin" && !s.find("c10")) s.fail("c10", "missing required key");
  if (m.law == "ogden" && !(s.find("mu") && s.find("alpha"))) s.fail(s.find("mu") ? "alpha" : "mu", "missing required key");
  if (m.law == "biphasic") {
    m.cubic = s.required("cubic", s.non_negative("cubic"));
    m.critical_strain = s.required("critical_strain", s.number("critical_strain"));
    if (!(m.critical_strain > 0 && m.critical_strain < 1))
      s.fail("critical_strain", "must be in (0, 1), got " + format_number(m.critical_strain), "e.g. 0.1");
  }
  if (m.law != "linear" && m.law != "biphasic" && !m.rigid) {
    std::string unstable;
    try {
      unstable = unstable_range(law_of(m));  // parameters that make no material fail here, at their line
    } catch (const Error& e) {
      const std::string key = e.location().substr(e.location().rfind('.') + 1);
      s.fail(s.find(key) ? key : "law", e.problem(), e.hint());
    }
    if (!unstable.empty()) {
      // A law that softens within tissue's strains has no stable equilibrium there: runs of it
      // blow up whatever the time step.
      const bool mr = m.law == "mooney-rivlin";
      s.fail(mr ? "c01" : "mu",
             "these " + m.law + " parameters are not stable (their stiffness is not positive definite): the stress "
             "stops rising with the strain " + unstable,
             mr ? "keep c01 >= 0, or small against c10 (the law softens in compression when c10 + c01/stretch < 0)"
                : "give every term mu*alpha > 0");
    }
  }
  return m;
}

std::map<std::string, MaterialSpec> read_materials(const Section& s) {
  std::map<std::string, MaterialSpec> materials;
  for (const auto& [name, table] : s.named_tables()) materials[name] = read_material(name, table);
  return materials;
}

const NameTable<Integrator> kIntegrators = {
    {"heun", Integrator::Heun, {}},
    {"symplectic_euler", Integrator::SymplecticEuler, {}},
    {"euler", Integrator::SymplecticEuler, {}},
    {"relaxation", Integrator::Relaxation, {}},
};
const NameTable<Precision> kPrecisions = {{"float", Precision::Float, {}},
                                          {"double", Precision::Double, {}}};

/// `dt` is "auto" (empty) or a positive step in seconds.
std::optional<double> read_dt(const Section& s) {
  const toml::node* node = s.find("dt");
  if (node && node->is_string()) {
    if (node->as_string()->get() != "auto") s.fail("dt", "expected \"auto\" or a number > 0 (s)");
    return std::nullopt;
  }
  return s.positive("dt");
}

SolverSpec read_solver(const Section& s) {
  s.check_keys(
      {"integrator", "dt", "dt_safety", "precision", "damping", "dashpot_ratio", "check_every", "hourglass"});
  SolverSpec v;
  if (const auto* n = s.named("integrator", kIntegrators)) v.integrator = n->value;
  v.dt_s = read_dt(s);
  // Relaxation only needs stability, not accuracy: it runs closer to the (Gershgorin) limit.
  v.dt_safety = s.positive("dt_safety").value_or(v.integrator == Integrator::Relaxation ? 0.9 : v.dt_safety);
  if (v.dt_safety > 1) s.fail("dt_safety", "must be in (0, 1], got " + format_number(v.dt_safety));
  if (const auto* n = s.named("precision", kPrecisions)) v.precision = n->value;
  v.damping_per_s = s.non_negative("damping").value_or(v.damping_per_s);
  v.dashpot_ratio = s.non_negative("dashpot_ratio").value_or(v.dashpot_ratio);
  v.check_every = s.integer<int>("check_every", 1).value_or(v.check_every);
  v.hourglass = s.non_negative("hourglass").value_or(v.hourglass);
  return v;
}

GravitySpec read_gravity(const Section& s) {
  s.check_keys({"vector", "posture", "magnitude"});
  const std::optional<Vec3> vector = s.vec3("vector");
  const std::optional<std::string> posture = s.text("posture");
  if (vector && posture) {
    s.fail("posture", "give either 'gravity.vector' or 'gravity.posture', not both");
  }
  if (!vector && !posture) s.fail("vector", "[gravity] needs 'vector' or 'posture'");
  GravitySpec g;
  g.active = true;
  if (vector) {
    if (s.find("magnitude")) s.fail("magnitude", "'magnitude' applies only with 'posture'");
    g.acceleration_m_s2 = *vector;
    return g;
  }
  const double magnitude = s.positive("magnitude").value_or(kStandardGravity_m_s2);
  try {
    g.acceleration_m_s2 = gravity_for_posture(*posture) * (magnitude / kStandardGravity_m_s2);
  } catch (const Error& e) {
    s.fail("posture", e.problem(), e.hint());  // same error, now with its file location
  }
  g.posture = *posture;
  return g;
}

const NameTable<AnchorSpec::Kind> kAnchorKinds = {
    {"sphere", AnchorSpec::Kind::Sphere, {"kind", "center", "radius", "rpy_deg"}},
    {"halfspace", AnchorSpec::Kind::HalfSpace, {"kind", "point", "normal"}},
    {"box", AnchorSpec::Kind::Box, {"kind", "min", "max"}},
};

AnchorSpec read_anchor(const std::string& name, const Section& s) {
  AnchorSpec a;
  a.name = name;
  a.line = s.line();
  a.kind = s.kind(kAnchorKinds).value;
  switch (a.kind) {
    case AnchorSpec::Kind::Sphere:
      a.center_m = s.required("center", s.vec3("center"));
      a.radius_m = s.required("radius", s.positive("radius"));
      a.rpy_deg = s.vec3("rpy_deg").value_or(a.rpy_deg);
      break;
    case AnchorSpec::Kind::HalfSpace:
      a.point_m = s.required("point", s.vec3("point"));
      a.normal = s.required("normal", s.direction("normal"));
      break;
    case AnchorSpec::Kind::Box:
      read_box(s, a.min_m, a.max_m);
      break;
  }
  return a;
}

const NameTable<IndenterSpec::Kind> kIndenterKinds = {
    {"sphere", IndenterSpec::Kind::Sphere, {"kind", "radius", "start", "velocity", "travel_time", "path", "contact", "friction",
                   "contact_surface", "contact_stiffness"}},
    {"plate", IndenterSpec::Kind::Plate, {"kind", "start", "normal", "velocity", "travel_time", "path", "contact", "friction",
                   "contact_surface", "contact_stiffness"}},
    {"cylinder", IndenterSpec::Kind::Cylinder,
     {"kind", "radius", "axis", "start", "velocity", "travel_time", "path", "contact", "friction",
                   "contact_surface", "contact_stiffness"}},
    {"capsule", IndenterSpec::Kind::Capsule,
     {"kind", "radius", "axis", "length", "start", "velocity", "travel_time", "path", "contact", "friction",
                   "contact_surface", "contact_stiffness"}},
};

const NameTable<IndenterSpec::Surface> kContactSurfaces = {
    {"vertices", IndenterSpec::Surface::Vertices, {}},
    {"triangles", IndenterSpec::Surface::Triangles, {}},
};

const NameTable<IndenterSpec::Contact> kContacts = {
    {"push", IndenterSpec::Contact::Push, {}},
    {"slide", IndenterSpec::Contact::Slide, {}},
    {"stick", IndenterSpec::Contact::Stick, {}},
};

IndenterSpec read_indenter(const Section& s, const std::string& scene_dir) {
  IndenterSpec i;
  i.has_start = false;
  i.line = s.line();
  i.kind = s.kind(kIndenterKinds).value;
  if (i.kind != IndenterSpec::Kind::Plate) i.radius_m = s.required("radius", s.positive("radius"));
  if (i.kind == IndenterSpec::Kind::Plate) i.normal = s.required("normal", s.direction("normal"));
  if (i.kind == IndenterSpec::Kind::Cylinder || i.kind == IndenterSpec::Kind::Capsule)
    i.normal = s.required("axis", s.direction("axis"));
  if (i.kind == IndenterSpec::Kind::Capsule) i.length_m = s.required("length", s.positive("length"));
  if (const auto* n = s.named("contact", kContacts)) i.contact = n->value;
  i.friction = s.non_negative("friction").value_or(0.0);
  if (i.friction > 0 && i.contact != IndenterSpec::Contact::Push)
    s.fail("friction", "applies to contact = \"push\" only", "'slide' is frictionless and 'stick' has no slip: remove 'friction'");
  if (const auto* n = s.named("contact_surface", kContactSurfaces)) i.contact_surface = n->value;
  if (const auto k = s.positive("contact_stiffness")) {
    if (i.contact_surface != IndenterSpec::Surface::Triangles)
      s.fail("contact_stiffness", "is the penalty of triangle contact", "set contact_surface = \"triangles\" or remove it");
    i.contact_stiffness = *k;
  }
  if (i.contact_surface == IndenterSpec::Surface::Triangles) {
    if (i.kind != IndenterSpec::Kind::Sphere)
      s.fail("contact_surface", "\"triangles\" is built for spheres only (a point probe)",
             "use kind = \"sphere\", or contact_surface = \"vertices\" for plates, cylinders and capsules");
    if (i.contact != IndenterSpec::Contact::Push)
      s.fail("contact", "triangle contact is unilateral (push)", "remove 'contact' or use contact_surface = \"vertices\"");
  }
  if (const auto path = s.text("path")) {
    for (const char* key : {"start", "velocity", "travel_time"})
      if (s.find(key)) s.fail(key, "a trajectory ('path') gives the positions already", "remove '" + std::string(key) + "'");
    std::filesystem::path file(*path);
    if (file.is_relative()) file = std::filesystem::path(scene_dir) / file;
    i.path_file = file.lexically_normal().string();
    try {
      i.path = read_indenter_path_csv(i.path_file);
    } catch (const Error& e) {
      s.fail("path", e.what());
    }
    i.start_m = i.path.front().position_m;
    return i;
  }
  // [probe] places its indenter itself; every other indenter needs a start (checked once [probe] is read)
  if (const auto start = s.vec3("start")) i.start_m = *start, i.has_start = true;
  i.velocity_m_s = s.vec3("velocity").value_or(i.velocity_m_s);
  i.travel_time_s = s.positive("travel_time").value_or(i.travel_time_s);
  return i;
}

// ---- the immobilisation device and positioning (docs/SCENE.md, [[device.torus]]) -------------

/// `key = [[a, b, ...], ...]`: rows of `width` finite numbers (at least one row); absent → nullopt.
std::optional<std::vector<std::vector<double>>> number_rows(const Section& s, std::string_view key, std::size_t width,
                                                            const std::string& row_shape) {
  const toml::node* node = s.find(key);
  if (!node) return std::nullopt;
  const toml::array* rows = node->as_array();
  if (!rows || rows->empty()) s.fail(key, "expected an array of rows " + row_shape + ", got " + describe(*node));
  std::vector<std::vector<double>> out;
  for (std::size_t i = 0; i < rows->size(); ++i) {
    const toml::array* row = rows->get(i)->as_array();
    const std::string which = "row " + std::to_string(i + 1) + " ";
    if (!row || row->size() != width)
      s.fail(key, which + "must be " + row_shape + ", got " + describe(*rows->get(i)));
    out.emplace_back();
    for (const toml::node& n : *row) {
      const std::optional<double> x = as_double(n);
      if (!x || !std::isfinite(*x)) s.fail(key, which + "must hold finite numbers " + row_shape + ", got " + describe(n));
      out.back().push_back(*x);
    }
  }
  return out;
}

/// Inflation knots from minor_radius (constant), inflate = [[t, r], ...] (with major_radius) or
/// inner_outer = [[t, inner, outer], ...]; exactly one of the three.
std::vector<TorusKnot> read_torus_schedule(const Section& s) {
  const bool has_minor = s.find("minor_radius"), has_inflate = s.find("inflate"), has_io = s.find("inner_outer");
  if (int(has_minor) + int(has_inflate) + int(has_io) != 1)
    s.fail(has_io ? "inner_outer" : has_inflate ? "inflate" : "minor_radius",
           has_minor || has_inflate || has_io ? "give only one of 'minor_radius', 'inflate' and 'inner_outer'"
                                              : "missing the tube size",
           "minor_radius = r (m), or inflate = [[t_s, r_m], ...], or inner_outer = [[t_s, inner_m, outer_m], ...]");
  std::vector<TorusKnot> knots;
  if (has_io) {
    if (s.find("major_radius")) s.fail("major_radius", "'inner_outer' sets the major radius already", "remove 'major_radius'");
    const auto rows = *number_rows(s, "inner_outer", 3, "[t_s, inner_m, outer_m]");
    for (const auto& row : rows) {
      if (!(row[1] > 0 && row[2] > row[1]))
        s.fail("inner_outer", "at t = " + format_number(row[0]) + " s: need 0 < inner < outer, got inner " +
                                  format_number(row[1]) + " m, outer " + format_number(row[2]) + " m");
      knots.push_back({row[0], 0.5 * (row[2] - row[1]), 0.5 * (row[2] + row[1])});
    }
  } else {
    const double major = s.required("major_radius", s.positive("major_radius"));
    if (has_minor) {
      knots.push_back({0.0, s.required("minor_radius", s.positive("minor_radius")), major});
    } else {
      const auto rows = *number_rows(s, "inflate", 2, "[t_s, minor_radius_m]");
      for (const auto& row : rows) {
        if (!(row[1] > 0)) s.fail("inflate", "at t = " + format_number(row[0]) + " s: the minor radius must be > 0");
        knots.push_back({row[0], row[1], major});
      }
    }
  }
  const std::string key = has_io ? "inner_outer" : has_inflate ? "inflate" : "minor_radius";
  for (std::size_t i = 0; i < knots.size(); ++i) {
    const TorusKnot& k = knots[i];
    if (k.time_s < 0) s.fail(key, "times must be ≥ 0 s, got " + format_number(k.time_s));
    if (i > 0 && !(k.time_s > knots[i - 1].time_s))
      s.fail(key, "times must increase strictly, got " + format_number(knots[i - 1].time_s) + " s then " +
                      format_number(k.time_s) + " s");
    if (!(k.minor_radius_m < k.major_radius_m))
      s.fail(key, "the minor radius " + format_number(k.minor_radius_m) + " m must be smaller than the major radius " +
                      format_number(k.major_radius_m) + " m" + (knots.size() > 1 ? " (at t = " + format_number(k.time_s) + " s)" : ""),
             "a tube that reaches the axis is not a ring torus");
  }
  return knots;
}

TorusSpec read_torus(const Section& s, std::size_t index, const std::vector<TorusSpec>& earlier) {
  s.check_keys({"name", "center", "axis", "major_radius", "minor_radius", "inflate", "inner_outer", "friction"});
  TorusSpec t;
  t.line = s.line();
  t.name = s.text("name").value_or("torus_" + std::to_string(index + 1));
  const auto bad_char = [](char c) { return !(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-'); };
  if (t.name.empty() || std::any_of(t.name.begin(), t.name.end(), bad_char))
    s.fail("name", "must be letters, digits, '_' or '-' (it names the device mesh files)");
  for (const TorusSpec& other : earlier)
    if (other.name == t.name) s.fail("name", "duplicate torus name '" + t.name + "'", "first used at line " + std::to_string(other.line));
  t.center_m = s.required("center", s.vec3("center"));
  t.axis = s.required("axis", s.direction("axis"));
  t.schedule = read_torus_schedule(s);
  t.friction = s.non_negative("friction").value_or(0.0);
  return t;
}

std::vector<TorusSpec> read_device(const Section& s) {
  s.check_keys({"torus"});
  std::vector<TorusSpec> tori;
  for (const Section& t : s.tables("torus")) tori.push_back(read_torus(t, tori.size(), tori));
  return tori;
}

PositioningSpec read_positioning(const Section& s, const std::vector<AnchorSpec>& anchors) {
  s.check_keys({"tumour_tissue", "target", "chest_wall"});
  PositioningSpec p;
  p.line = s.line();
  p.tumour_tissue = s.text("tumour_tissue").value_or("");
  if (s.find("tumour_tissue") && p.tumour_tissue.empty()) s.fail("tumour_tissue", "must not be empty");
  p.target_m = s.vec3("target");
  p.chest_wall = s.text("chest_wall").value_or("");
  if (s.find("chest_wall")) {
    const auto it = std::find_if(anchors.begin(), anchors.end(), [&](const AnchorSpec& a) { return a.name == p.chest_wall; });
    Keys names;
    for (const AnchorSpec& a : anchors) names.push_back(a.name);
    if (it == anchors.end()) s.fail("chest_wall", "names no [anchor." + p.chest_wall + "]", choice_hint(p.chest_wall, names));
    if (it->kind == AnchorSpec::Kind::Box)
      s.fail("chest_wall", "anchor '" + p.chest_wall + "' is a box", "the chest wall is a sphere or halfspace anchor");
  }
  return p;
}

std::vector<TrackSpec> read_tracks(const std::vector<Section>& sections) {
  std::vector<TrackSpec> tracks;
  for (const Section& s : sections) {
    s.check_keys({"name", "point"});
    TrackSpec t;
    t.name = s.required("name", s.text("name"));
    t.point_m = s.required("point", s.vec3("point"));
    t.line = s.line();
    const auto same = std::find_if(tracks.begin(), tracks.end(),
                                   [&](const TrackSpec& other) { return other.name == t.name; });
    if (same != tracks.end()) {
      s.fail("name", "duplicate track name '" + t.name + "'",
             "first used at line " + std::to_string(same->line));
    }
    tracks.push_back(t);
  }
  return tracks;
}

/// [probe] (docs/SCENE.md): a line of quasi-static presses with one of the indenters.
ProbeSpec read_probe(const Section& s, const std::vector<IndenterSpec>& indenters) {
  s.check_keys({"indenter", "from", "to", "presses", "direction", "depth", "steps", "from_contact", "at_force"});
  ProbeSpec p;
  p.active = true;
  p.line = s.line();
  const int which = s.integer<int>("indenter", 1).value_or(1);
  if (std::size_t(which) > indenters.size())
    s.fail("indenter", "names indenter " + std::to_string(which) + " but the scene has " +
                           std::to_string(indenters.size()) + " [[indenter]] tables",
           "indenters count from 1 in file order");
  p.indenter = std::size_t(which - 1);
  if (indenters[p.indenter].kind == IndenterSpec::Kind::Plate)
    s.fail("indenter", "a plate cannot probe a line of points", "use a sphere, cylinder or capsule indenter");
  if (!indenters[p.indenter].path.empty())
    s.fail("indenter", "the probing indenter has a recorded trajectory ('path')", "[probe] moves it itself: remove the path");
  p.from_m = s.required("from", s.vec3("from"));
  p.to_m = s.vec3("to").value_or(p.from_m);
  p.presses = s.integer<int>("presses", 1).value_or(p.presses);
  if (p.presses == 1 && s.find("to") && (p.to_m - p.from_m).norm() > 0)
    s.fail("presses", "one press with a 'to' point", "give presses ≥ 2 for a line, or leave out 'to'");
  p.direction = s.direction("direction").value_or(p.direction);
  p.depth_m = s.required("depth", s.positive("depth"));
  p.steps = s.integer<int>("steps", 1).value_or(p.steps);
  p.from_contact = s.boolean("from_contact").value_or(p.from_contact);
  if (const toml::node* node = s.find("at_force")) {
    const toml::array* array = node->as_array();
    if (!array) s.fail("at_force", "expected an array of forces (N)");
    for (const toml::node& n : *array) {
      const std::optional<double> x = as_double(n);
      if (!x || !(*x > 0)) s.fail("at_force", "forces must be positive numbers (N)");
      p.at_force_n.push_back(*x);
    }
  }
  return p;
}

StopSpec read_stop(const Section& s) {
  s.check_keys({"equilibrium", "max_steps", "time"});
  StopSpec stop;
  stop.equilibrium = s.non_negative("equilibrium").value_or(stop.equilibrium);
  stop.max_steps = s.integer<std::int64_t>("max_steps", 1).value_or(stop.max_steps);
  stop.max_time_s = s.positive("time").value_or(stop.max_time_s);
  return stop;
}

const NameTable<VolumeSpec::Predictor> kVolumePredictors = {{"pressure", VolumeSpec::Predictor::Pressure, {}},
                                                              {"projection", VolumeSpec::Predictor::Projection, {}}};

VolumeSpec read_volume(const Section& s) {
  s.check_keys({"preserve", "every", "predictor"});
  VolumeSpec volume;
  volume.preserve = s.boolean("preserve").value_or(volume.preserve);
  volume.every = s.integer<int>("every", 1).value_or(volume.every);
  if (const auto* n = s.named("predictor", kVolumePredictors)) volume.predictor = n->value;
  volume.line = s.line();
  return volume;
}

ReferenceStateSpec read_reference_state(const Section& s) {
  s.check_keys({"ct_posture", "ct_gravity", "tolerance_mm", "max_iterations"});
  ReferenceStateSpec r;
  r.active = true;
  r.line = s.line();
  const std::optional<std::string> posture = s.text("ct_posture");
  const std::optional<Vec3> vector = s.vec3("ct_gravity");
  if (posture && vector) s.fail("ct_gravity", "give either 'ct_posture' or 'ct_gravity', not both");
  if (!posture && !vector)
    s.fail("ct_posture", "[reference_state] needs the CT's posture", "e.g. ct_posture = \"supine\"");
  if (vector) r.ct_gravity_m_s2 = *vector;
  if (posture) {
    try {
      r.ct_gravity_m_s2 = gravity_for_posture(*posture);
    } catch (const Error& e) {
      s.fail("ct_posture", e.problem(), e.hint());
    }
    r.ct_posture = *posture;
  }
  if (const auto mm = s.positive("tolerance_mm")) r.tolerance_m = *mm * 1e-3;
  r.max_iterations = s.integer<int>("max_iterations", 1).value_or(r.max_iterations);
  return r;
}

ReproducibilitySpec read_reproducibility(const Section& s, const std::vector<AnchorSpec>& anchors) {
  s.check_keys({"perturbations", "max_angle_deg", "seed"});
  ReproducibilitySpec r;
  r.active = true;
  r.line = s.line();
  r.perturbations = s.integer<int>("perturbations", 2).value_or(r.perturbations);
  r.max_angle_deg = s.positive("max_angle_deg").value_or(r.max_angle_deg);
  if (r.max_angle_deg > 45) s.fail("max_angle_deg", "is meant for small day-to-day posture changes", "use at most 45");
  r.seed = std::uint64_t(s.integer<std::int64_t>("seed", 0).value_or(std::int64_t(r.seed)));
  if (std::none_of(anchors.begin(), anchors.end(), [](const AnchorSpec& a) { return a.kind == AnchorSpec::Kind::Sphere; }))
    s.fail("perturbations", "perturbs the pose of the chest-wall sphere anchor, and the scene has none",
           "add [anchor.NAME] kind = \"sphere\" (docs/POSITIONING.md)");
  return r;
}

const NameTable<bool> kDvfNiftiLayouts = {{"standard", false, {}}, {"legacy", true, {}}};  // value: legacy

OutputSpec read_output(const Section& s, const ModelSpec& model) {
  s.check_keys({"frames_every", "dvf", "dvf_nifti", "dvf_dicom", "warped_ct", "warped_ct_dicom", "fields", "surfaces"});
  OutputSpec out;
  out.frames_every = s.integer<int>("frames_every", 0).value_or(out.frames_every);
  for (const char* key : {"dvf", "dvf_nifti", "dvf_dicom", "warped_ct", "warped_ct_dicom", "fields"}) {
    if (s.find(key) && !model.from_image()) s.fail(key, "needs a CT image model (model.image)");
  }
  out.dvf = s.boolean("dvf").value_or(out.dvf);
  (void)s.named("dvf_nifti", kDvfNiftiLayouts);  // checked here, read by dvf_file_options
  if (s.find("dvf_nifti") && !out.dvf) s.fail("dvf_nifti", "sets the layout of the DVF files, but dvf = false writes none");
  out.warped_ct = s.boolean("warped_ct").value_or(out.warped_ct);
  out.warped_ct_dicom = s.boolean("warped_ct_dicom").value_or(out.warped_ct_dicom);
  if (s.boolean("dvf_dicom").value_or(false) && !out.warped_ct_dicom)
    s.fail("dvf_dicom", "the DICOM registration references the warped CT series, but warped_ct_dicom = false",
           "set warped_ct_dicom = true, or leave dvf_dicom out");
  out.fields = s.boolean("fields").value_or(out.fields);
  out.surfaces = s.boolean("surfaces").value_or(out.surfaces);
  return out;
}

/// Runs after everything is read: shapes may come before the materials they name. A tissue
/// needs a [materials.X] table unless it has a default material.
void check_labels(Scene& scene, const std::string& source, const StructureSpec& structures) {
  const std::vector<std::string> defaults = default_material_names();  // outlives the views in `names`
  Keys names;
  for (const auto& entry : scene.materials) names.push_back(entry.first);
  for (const std::string& d : defaults) names.push_back(d);
  auto resolve = [&](const std::string& tissue, int line, const std::string& key) {
    if (scene.materials.count(tissue) || tissue == "air") return;  // "air": not modelled
    if (auto d = default_material(tissue)) {
      scene.materials[tissue] = *d;
      return;
    }
    const std::string guess = did_you_mean(tissue, names);
    throw Error("label '" + tissue + "' names no [materials." + tissue + "] table and has no default material",
                where_string(source, line, key), guess.empty() ? "define [materials." + tissue + "] with 'E'" : guess);
  };
  for (std::size_t i = 0; i < scene.model.shapes.size(); ++i)
    resolve(scene.model.shapes[i].label, scene.model.shapes[i].line, "model.shape[" + std::to_string(i) + "].label");
  for (const auto& [value, tissue] : scene.model.label_table)
    resolve(tissue, scene.model.line, "model.label_table." + std::to_string(value));
  for (const auto& [roi, tissue] : structures.table)
    if (tissue != "ignore") resolve(tissue, scene.model.line, "model.structure_table." + roi);
  for (std::size_t i = 0; i < scene.model.hu_classes.size(); ++i)
    resolve(scene.model.hu_classes[i].tissue, scene.model.hu_classes[i].line, "model.hu_class[" + std::to_string(i) + "].tissue");
}

/// Relative data paths in a scene file are relative to the scene file's folder.
void resolve_paths(ModelSpec& model, const std::string& scene_path) {
  const std::filesystem::path base = std::filesystem::path(scene_path).parent_path();
  for (std::string* p : {&model.image_path, &model.labels_path}) {
    if (!p->empty() && std::filesystem::path(*p).is_relative()) *p = (base / *p).lexically_normal().string();
  }
}

std::string read_text_file(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw Error("scene file not found (or not a regular file)", path, "check the path");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot open the scene file", path, "check the file's permissions");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw Error("cannot read the scene file", path);
  return text;
}

}  // namespace

Scene parse_scene_text(const std::string& text, const std::string& source_name) {
  const toml::table root = parse_toml_text(text, source_name);
  const Section top(root, "", source_name);
  top.check_keys(
      {"model", "materials", "solver", "gravity", "anchor", "indenter", "device", "positioning", "track", "stop",
       "output", "volume", "reference_state", "reproducibility", "probe", "fit"});  // [fit]: read by `voxbreast fit` (io/fit_file.hpp)
  Scene scene;
  scene.model = read_model(top.table_or_empty("model"));
  scene.materials = read_materials(top.table_or_empty("materials"));
  scene.solver = read_solver(top.table_or_empty("solver"));
  if (const auto gravity = top.table("gravity")) scene.gravity = read_gravity(*gravity);
  for (const auto& [name, s] : top.table_or_empty("anchor").named_tables()) {
    scene.anchors.push_back(read_anchor(name, s));
  }
  const std::string scene_dir = std::filesystem::path(source_name).parent_path().string();
  for (const Section& s : top.tables("indenter")) scene.indenters.push_back(read_indenter(s, scene_dir));
  if (const auto device = top.table("device")) scene.tori = read_device(*device);
  if (const auto positioning = top.table("positioning")) scene.positioning = read_positioning(*positioning, scene.anchors);
  scene.tracks = read_tracks(top.tables("track"));
  scene.stop = read_stop(top.table_or_empty("stop"));
  scene.output = read_output(top.table_or_empty("output"), scene.model);
  if (const auto volume = top.table("volume")) scene.volume = read_volume(*volume);
  if (const auto r = top.table("reference_state")) scene.reference_state = read_reference_state(*r);
  if (const auto r = top.table("reproducibility")) scene.reproducibility = read_reproducibility(*r, scene.anchors);
  if (scene.reference_state.active && !scene.gravity.active)
    top.fail("reference_state", "[reference_state] needs a [gravity] section: the posture the run goes to");
  if (const auto probe = top.table("probe")) scene.probe = read_probe(*probe, scene.indenters);
  for (std::size_t i = 0; i < scene.indenters.size(); ++i)
    if (!scene.indenters[i].has_start && scene.indenters[i].path.empty() && !(scene.probe.active && scene.probe.indenter == i))
      throw Error("missing required key", where_string(source_name, scene.indenters[i].line, "indenter[" + std::to_string(i) + "].start"),
                  "only the [probe] indenter may leave out 'start'");
  check_labels(scene, source_name, read_structure_spec(top.table_or_empty("model")));
  scene.source_text = text;
  return scene;
}

const std::vector<std::string>& scene_path_keys() {
  // model.image and model.labels as resolve_paths; model.structures as scene_structures
  static const std::vector<std::string> keys = {"model.image", "model.labels", "model.structures"};
  return keys;
}

StructureSpec scene_structures(const Scene& scene) {
  const toml::table root = parse_toml_text(scene.source_text, scene.source_path);
  StructureSpec spec = read_structure_spec(Section(root, "", scene.source_path).table_or_empty("model"));
  if (!spec.path.empty() && std::filesystem::path(spec.path).is_relative())
    spec.path = (std::filesystem::path(scene.source_path).parent_path() / spec.path).lexically_normal().string();
  return spec;
}

DvfFileOptions dvf_file_options(const Scene& scene) {
  DvfFileOptions options;
  const toml::table root = parse_toml_text(scene.source_text, scene.source_path);
  const toml::table* output = root["output"].as_table();
  if (!output) return options;
  options.legacy_nifti = output->get_as<std::string>("dvf_nifti") && **output->get_as<std::string>("dvf_nifti") == "legacy";
  options.dicom = (*output)["dvf_dicom"].value_or(scene.output.warped_ct_dicom) && scene.output.warped_ct_dicom;
  return options;
}

Scene parse_scene_file(const std::string& path) { return parse_scene_file(path, {}); }

Scene parse_scene_file(const std::string& path, const std::vector<SceneOverride>& overrides) {
  std::string text = read_text_file(path);
  if (!overrides.empty()) text = apply_scene_overrides(text, path, overrides);
  Scene scene = parse_scene_text(text, path);
  scene.source_path = path;
  resolve_paths(scene.model, path);
  return scene;
}

}  // namespace vb
