#include "triangulation/georef/crs.h"

#include "calib/core/error.h"

#include <cmath>
#include <filesystem>
#include <limits>
#include <proj.h>
#include <proj_experimental.h>  // compound / 3D CRS construction (stable since PROJ 6)
#include <set>
#include <utility>
#include <vector>

namespace aerocal::triangulation {
namespace {

struct PjDeleter {
  void operator()(PJ* p) const { proj_destroy(p); }
};
using PjPtr = std::unique_ptr<PJ, PjDeleter>;

bool IsGeographic(PJ_TYPE t) {
  return t == PJ_TYPE_GEOGRAPHIC_2D_CRS || t == PJ_TYPE_GEOGRAPHIC_3D_CRS ||
         t == PJ_TYPE_GEOGRAPHIC_CRS;
}

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string ContextError(PJ_CONTEXT* ctx) {
  return proj_context_errno_string(ctx, proj_context_errno(ctx));
}

// Every error of the set-up: `where: what` (the option or the project file's frame entry).
[[noreturn]] void Fail(const std::string& where, const std::string& what) {
  throw InputError(where + ": " + what);
}

// The file's CRS (with the vertical CRS when one is given apart); `definition` gets its name.
PjPtr ReadSourceCrs(PJ_CONTEXT* ctx,
                    const CrsOptions& o,
                    const std::string& where,
                    std::string* definition_name) {
  if (o.definition.empty()) Fail(where, "no CRS given (an EPSG code, WKT or PROJ string)");
  // A PROJ string as ODM's gcp_list.txt writes it ("+proj=utm +zone=22 +south ...") is a CRS
  // only with +type=crs.
  std::string definition = o.definition;
  if (definition.rfind("+proj=", 0) == 0 && definition.find("+type=crs") == std::string::npos)
    definition += " +type=crs";
  PjPtr source(proj_create(ctx, definition.c_str()));
  if (!source || !proj_is_crs(source.get()))
    Fail(where, "PROJ cannot read '" + o.definition + "' as a CRS (" + ContextError(ctx) + ")");
  if (o.vertical.empty()) return source;
  if (!o.geoid_grid.empty()) Fail(where, "give a vertical CRS or a geoid grid, not both");
  PjPtr vertical(proj_create(ctx, o.vertical.c_str()));
  if (!vertical || proj_get_type(vertical.get()) != PJ_TYPE_VERTICAL_CRS)
    Fail(where, "PROJ cannot read '" + o.vertical + "' as a vertical CRS");
  const PJ_TYPE t = proj_get_type(source.get());
  if (!(t == PJ_TYPE_PROJECTED_CRS || t == PJ_TYPE_GEOGRAPHIC_2D_CRS))
    Fail(where,
         "a separate vertical CRS needs a 2D horizontal CRS ('" + o.definition +
             "' is not one; use a compound CRS instead)");
  source.reset(proj_create_compound_crs(
      ctx, (o.definition + " + " + o.vertical).c_str(), source.get(), vertical.get()));
  if (!source) Fail(where, "PROJ cannot combine '" + o.definition + "' and '" + o.vertical + "'");
  *definition_name += " + " + o.vertical;
  return source;
}

// The horizontal (or geocentric) part decides the axes of the file's coordinates.
CrsConverter::Axes AxesOf(PJ_CONTEXT* ctx,
                          PJ* source,
                          const CrsOptions& o,
                          const std::string& where) {
  PjPtr horizontal(proj_get_type(source) == PJ_TYPE_COMPOUND_CRS
                       ? proj_crs_get_sub_crs(ctx, source, 0)
                       : proj_clone(ctx, source));
  if (horizontal && proj_get_type(horizontal.get()) == PJ_TYPE_BOUND_CRS)
    horizontal.reset(proj_get_source_crs(ctx, horizontal.get()));
  if (!horizontal) Fail(where, "'" + o.definition + "' has no horizontal CRS");
  const PJ_TYPE ht = proj_get_type(horizontal.get());
  if (IsGeographic(ht)) return CrsConverter::Axes::kGeographic;
  if (ht == PJ_TYPE_PROJECTED_CRS) return CrsConverter::Axes::kProjected;
  if (ht == PJ_TYPE_GEOCENTRIC_CRS) return CrsConverter::Axes::kGeocentric;
  Fail(where, "'" + o.definition + "' is no geographic, projected or geocentric CRS");
}

// The pivot: the geographic 3D CRS of the file's own datum unless one is given.
PjPtr PivotCrs(PJ_CONTEXT* ctx,
               PJ* source,
               const std::string& pivot_definition,
               const CrsOptions& o,
               const std::string& where) {
  PjPtr pivot;
  if (pivot_definition.empty()) {
    PjPtr geodetic(proj_crs_get_geodetic_crs(ctx, source));
    if (!geodetic) Fail(where, "'" + o.definition + "' has no geodetic datum");
    if (proj_get_type(geodetic.get()) == PJ_TYPE_GEOCENTRIC_CRS) {
      PjPtr datum(proj_crs_get_datum_forced(ctx, geodetic.get()));
      PjPtr cs(proj_create_ellipsoidal_3D_cs(
          ctx, PJ_ELLPS3D_LONGITUDE_LATITUDE_HEIGHT, nullptr, 0, nullptr, 0));
      pivot.reset(proj_create_geographic_crs_from_datum(
          ctx,
          (std::string(proj_get_name(geodetic.get())) + " (geographic 3D)").c_str(),
          datum.get(),
          cs.get()));
    } else {
      pivot.reset(proj_crs_promote_to_3D(ctx, nullptr, geodetic.get()));
    }
  } else {
    pivot.reset(proj_create(ctx, pivot_definition.c_str()));
  }
  if (!pivot)
    Fail(where, "no geographic 3D CRS for '" + o.definition + "' (" + ContextError(ctx) + ")");
  return pivot;
}

// Semi-major axis a (m) and flattening f of the pivot's ellipsoid.
void EllipsoidOf(PJ_CONTEXT* ctx,
                 PJ* pivot,
                 const CrsOptions& o,
                 const std::string& where,
                 double* a,
                 double* f) {
  PjPtr ellipsoid(proj_get_ellipsoid(ctx, pivot));
  double b = 0, inv_f = 0;
  int computed = 0;
  if (!ellipsoid || !proj_ellipsoid_get_parameters(ctx, ellipsoid.get(), a, &b, &computed, &inv_f))
    Fail(where, "no ellipsoid for '" + o.definition + "'");
  *f = inv_f > 0 ? 1.0 / inv_f : 0.0;
}

// The operations from source to pivot that PROJ knows, best first.
std::vector<PjPtr> Operations(PJ_CONTEXT* ctx,
                              PJ* source,
                              PJ* pivot,
                              PROJ_GRID_AVAILABILITY_USE use) {
  PJ_OPERATION_FACTORY_CONTEXT* factory = proj_create_operation_factory_context(ctx, nullptr);
  proj_operation_factory_context_set_grid_availability_use(ctx, factory, use);
  proj_operation_factory_context_set_spatial_criterion(
      ctx, factory, PROJ_SPATIAL_CRITERION_PARTIAL_INTERSECTION);
  PJ_OBJ_LIST* list = proj_create_operations(ctx, source, pivot, factory);
  proj_operation_factory_context_destroy(factory);
  std::vector<PjPtr> out;
  for (int i = 0; list && i < proj_list_get_count(list); ++i)
    out.emplace_back(proj_list_get(ctx, list, i));
  if (list) proj_list_destroy(list);
  return out;
}

bool VerticalBallpark(PJ* op) {
  return Lower(proj_get_name(op)).find("ballpark vertical") != std::string::npos;
}

// The grids an operation uses: short name (may be null) and whether it is installed.
std::vector<std::pair<const char*, bool>> GridsUsed(PJ_CONTEXT* ctx, PJ* op) {
  std::vector<std::pair<const char*, bool>> grids;
  for (int g = 0; g < proj_coordoperation_get_grid_used_count(ctx, op); ++g) {
    const char *short_name = nullptr, *full_name = nullptr, *package = nullptr, *url = nullptr;
    int direct = 0, open = 0, available = 0;
    proj_coordoperation_get_grid_used(
        ctx, op, g, &short_name, &full_name, &package, &url, &direct, &open, &available);
    grids.emplace_back(short_name, available != 0);
  }
  return grids;
}

std::vector<std::string> MissingGrids(PJ_CONTEXT* ctx, PJ* op) {
  std::vector<std::string> names;
  for (const auto& [name, available] : GridsUsed(ctx, op))
    if (!available && name) names.emplace_back(name);
  return names;
}

// The operation: the best one whose grids are installed. With orthometric heights the geoid
// grid is required; a ballpark vertical transformation (heights unchanged) is refused.
PjPtr ChooseOperation(PJ_CONTEXT* ctx,
                      PJ* source,
                      PJ* pivot,
                      bool orthometric,
                      const CrsOptions& o,
                      const std::string& where,
                      const std::string& definition_name) {
  for (auto& op :
       Operations(ctx, source, pivot, PROJ_GRID_AVAILABILITY_DISCARD_OPERATION_IF_MISSING_GRID)) {
    if (!proj_coordoperation_is_instantiable(ctx, op.get())) continue;
    if (orthometric && o.geoid_grid.empty() && VerticalBallpark(op.get())) continue;
    if (!MissingGrids(ctx, op.get()).empty()) continue;
    return std::move(op);
  }
  std::set<std::string> missing;
  for (auto& op : Operations(ctx, source, pivot, PROJ_GRID_AVAILABILITY_IGNORED))
    for (const auto& g : MissingGrids(ctx, op.get())) missing.insert(g);
  std::string names;
  for (const auto& g : missing) names += (names.empty() ? "" : ", ") + g;
  Fail(where,
       "no conversion of '" + definition_name + "' to ellipsoidal heights: " +
           (names.empty() ? std::string("PROJ knows no operation")
                          : "the geoid grid " + names + " is not installed") +
           " (PROJ searches " + proj_info().searchpath +
           "; install it there, or name a grid file with geoid_grid:)");
}

// The operation's name with the grids it uses.
std::string OperationName(PJ_CONTEXT* ctx, PJ* op) {
  std::string name = proj_get_name(op);
  bool first = true;
  for (const auto& [grid, available] : GridsUsed(ctx, op)) {
    name += std::string(first ? "; grids: " : ", ") + (grid ? grid : "?");
    first = false;
  }
  return name;
}

// The pipeline adding the undulation of a user's geoid grid to orthometric heights.
PjPtr GeoidPipeline(PJ_CONTEXT* ctx, const CrsOptions& o, const std::string& where) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(o.geoid_grid, ec))
    Fail(where, "geoid grid '" + o.geoid_grid + "' not found");
  const std::string path = std::filesystem::absolute(o.geoid_grid).string();
  const std::string pipeline =
      "+proj=pipeline +step +proj=unitconvert +xy_in=deg +xy_out=rad +step +proj=vgridshift "
      "+grids=" +
      path + " +multiplier=1 +step +proj=unitconvert +xy_in=rad +xy_out=deg";
  PjPtr geoid(proj_create(ctx, pipeline.c_str()));
  if (!geoid)
    Fail(where,
         "PROJ cannot read the geoid grid '" + o.geoid_grid + "' (" + ContextError(ctx) + ")");
  return geoid;
}

}  // namespace

struct CrsConverter::Impl {
  PJ_CONTEXT* ctx = nullptr;
  PjPtr source, pivot, operation, geoid;
  std::string pivot_wkt, definition, operation_name;
  double a = 0, f = 0;
  Axes axes = Axes::kProjected;
  bool orthometric = false;

  ~Impl() {
    geoid.reset();
    operation.reset();
    pivot.reset();
    source.reset();
    if (ctx) proj_context_destroy(ctx);
  }
  std::string LastError() const { return ContextError(ctx); }
};

CrsConverter::CrsConverter(const CrsOptions& o, const std::string& pivot_definition)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  const std::string where = o.where.empty() ? std::string("crs") : o.where;
  m.ctx = proj_context_create();
  proj_context_set_enable_network(m.ctx, 0);  // never download grids (PROJ_NETWORK=OFF)
  proj_log_level(m.ctx, PJ_LOG_NONE);
  m.definition = o.definition;
  m.source = ReadSourceCrs(m.ctx, o, where, &m.definition);
  m.axes = AxesOf(m.ctx, m.source.get(), o, where);
  m.orthometric = proj_get_type(m.source.get()) == PJ_TYPE_COMPOUND_CRS || !o.geoid_grid.empty();
  m.pivot = PivotCrs(m.ctx, m.source.get(), pivot_definition, o, where);
  const char* wkt = proj_as_wkt(m.ctx, m.pivot.get(), PJ_WKT2_2019, nullptr);
  m.pivot_wkt = wkt ? wkt : "";
  EllipsoidOf(m.ctx, m.pivot.get(), o, where, &m.a, &m.f);
  const PjPtr chosen =
      ChooseOperation(m.ctx, m.source.get(), m.pivot.get(), m.orthometric, o, where, m.definition);
  m.operation_name = OperationName(m.ctx, chosen.get());
  m.operation.reset(proj_normalize_for_visualization(m.ctx, chosen.get()));
  if (!m.operation) Fail(where, "PROJ cannot normalise the axis order (" + m.LastError() + ")");
  if (!o.geoid_grid.empty()) {
    m.geoid = GeoidPipeline(m.ctx, o, where);
    m.operation_name += "; heights + undulation of " + o.geoid_grid;
  }
}

CrsConverter::~CrsConverter() = default;
CrsConverter::CrsConverter(CrsConverter&&) noexcept = default;
CrsConverter& CrsConverter::operator=(CrsConverter&&) noexcept = default;

namespace {

Eigen::Vector3d Apply(PJ* op, PJ_DIRECTION direction, const Eigen::Vector3d& in) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (!in.allFinite()) return Eigen::Vector3d::Constant(nan);
  proj_errno_reset(op);
  const PJ_COORD out = proj_trans(op, direction, proj_coord(in.x(), in.y(), in.z(), HUGE_VAL));
  const Eigen::Vector3d v(out.xyz.x, out.xyz.y, out.xyz.z);
  if (proj_errno(op) != 0 || !v.allFinite() || v.cwiseAbs().maxCoeff() >= HUGE_VAL)
    return Eigen::Vector3d::Constant(nan);
  return v;
}

}  // namespace

Eigen::Vector3d CrsConverter::ToPivot(const Eigen::Vector3d& in) const {
  Eigen::Vector3d out = Apply(impl_->operation.get(), PJ_FWD, in);
  if (impl_->geoid) out = Apply(impl_->geoid.get(), PJ_FWD, out);
  return out;
}

Eigen::Vector3d CrsConverter::FromPivot(const Eigen::Vector3d& lon_lat_h) const {
  Eigen::Vector3d in = lon_lat_h;
  if (impl_->geoid) in = Apply(impl_->geoid.get(), PJ_INV, in);
  return Apply(impl_->operation.get(), PJ_INV, in);
}

const std::string& CrsConverter::PivotDefinition() const { return impl_->pivot_wkt; }
double CrsConverter::semi_major_m() const { return impl_->a; }
double CrsConverter::flattening() const { return impl_->f; }
CrsConverter::Axes CrsConverter::axes() const { return impl_->axes; }
bool CrsConverter::orthometric() const { return impl_->orthometric; }
std::string CrsConverter::Name() const { return proj_get_name(impl_->source.get()); }
std::string CrsConverter::Definition() const { return impl_->definition; }
std::string CrsConverter::OperationDescription() const { return impl_->operation_name; }

}  // namespace aerocal::triangulation
