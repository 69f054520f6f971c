#include "triangulation/georef/crs.h"

#include "calib/core/error.h"

#include <cmath>
#include <filesystem>
#include <limits>
#include <proj.h>
#include <proj_experimental.h>  // compound / 3D CRS construction (stable since PROJ 6)
#include <set>
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
  std::string LastError() const { return proj_context_errno_string(ctx, proj_context_errno(ctx)); }
};

CrsConverter::CrsConverter(const CrsOptions& o, const std::string& pivot_definition)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  const std::string where = o.where.empty() ? std::string("crs") : o.where;
  const auto fail = [&](const std::string& what) { throw InputError(where + ": " + what); };
  m.ctx = proj_context_create();
  proj_context_set_enable_network(m.ctx, 0);  // never download grids (PROJ_NETWORK=OFF)
  proj_log_level(m.ctx, PJ_LOG_NONE);
  m.definition = o.definition;
  if (o.definition.empty()) fail("no CRS given (an EPSG code, WKT or PROJ string)");
  // A PROJ string as ODM's gcp_list.txt writes it ("+proj=utm +zone=22 +south ...") is a CRS
  // only with +type=crs.
  std::string definition = o.definition;
  if (definition.rfind("+proj=", 0) == 0 && definition.find("+type=crs") == std::string::npos)
    definition += " +type=crs";
  m.source.reset(proj_create(m.ctx, definition.c_str()));
  if (!m.source || !proj_is_crs(m.source.get()))
    fail("PROJ cannot read '" + o.definition + "' as a CRS (" + m.LastError() + ")");
  if (!o.vertical.empty()) {
    if (!o.geoid_grid.empty()) fail("give a vertical CRS or a geoid grid, not both");
    PjPtr vertical(proj_create(m.ctx, o.vertical.c_str()));
    if (!vertical || proj_get_type(vertical.get()) != PJ_TYPE_VERTICAL_CRS)
      fail("PROJ cannot read '" + o.vertical + "' as a vertical CRS");
    const PJ_TYPE t = proj_get_type(m.source.get());
    if (!(t == PJ_TYPE_PROJECTED_CRS || t == PJ_TYPE_GEOGRAPHIC_2D_CRS))
      fail("a separate vertical CRS needs a 2D horizontal CRS ('" + o.definition +
           "' is not one; use a compound CRS instead)");
    m.source.reset(proj_create_compound_crs(
        m.ctx, (o.definition + " + " + o.vertical).c_str(), m.source.get(), vertical.get()));
    if (!m.source) fail("PROJ cannot combine '" + o.definition + "' and '" + o.vertical + "'");
    m.definition += " + " + o.vertical;
  }
  // The horizontal (or geocentric) part decides the axes of the file's coordinates.
  PjPtr horizontal(proj_get_type(m.source.get()) == PJ_TYPE_COMPOUND_CRS
                       ? proj_crs_get_sub_crs(m.ctx, m.source.get(), 0)
                       : proj_clone(m.ctx, m.source.get()));
  if (horizontal && proj_get_type(horizontal.get()) == PJ_TYPE_BOUND_CRS)
    horizontal.reset(proj_get_source_crs(m.ctx, horizontal.get()));
  if (!horizontal) fail("'" + o.definition + "' has no horizontal CRS");
  const PJ_TYPE ht = proj_get_type(horizontal.get());
  if (IsGeographic(ht))
    m.axes = Axes::kGeographic;
  else if (ht == PJ_TYPE_PROJECTED_CRS)
    m.axes = Axes::kProjected;
  else if (ht == PJ_TYPE_GEOCENTRIC_CRS)
    m.axes = Axes::kGeocentric;
  else
    fail("'" + o.definition + "' is no geographic, projected or geocentric CRS");
  m.orthometric = proj_get_type(m.source.get()) == PJ_TYPE_COMPOUND_CRS || !o.geoid_grid.empty();

  // The pivot: the geographic 3D CRS of the file's own datum unless one is given.
  if (pivot_definition.empty()) {
    PjPtr geodetic(proj_crs_get_geodetic_crs(m.ctx, m.source.get()));
    if (!geodetic) fail("'" + o.definition + "' has no geodetic datum");
    if (proj_get_type(geodetic.get()) == PJ_TYPE_GEOCENTRIC_CRS) {
      PjPtr datum(proj_crs_get_datum_forced(m.ctx, geodetic.get()));
      PjPtr cs(proj_create_ellipsoidal_3D_cs(
          m.ctx, PJ_ELLPS3D_LONGITUDE_LATITUDE_HEIGHT, nullptr, 0, nullptr, 0));
      m.pivot.reset(proj_create_geographic_crs_from_datum(
          m.ctx,
          (std::string(proj_get_name(geodetic.get())) + " (geographic 3D)").c_str(),
          datum.get(),
          cs.get()));
    } else {
      m.pivot.reset(proj_crs_promote_to_3D(m.ctx, nullptr, geodetic.get()));
    }
  } else {
    m.pivot.reset(proj_create(m.ctx, pivot_definition.c_str()));
  }
  if (!m.pivot) fail("no geographic 3D CRS for '" + o.definition + "' (" + m.LastError() + ")");
  const char* wkt = proj_as_wkt(m.ctx, m.pivot.get(), PJ_WKT2_2019, nullptr);
  m.pivot_wkt = wkt ? wkt : "";
  {
    PjPtr ellipsoid(proj_get_ellipsoid(m.ctx, m.pivot.get()));
    double b = 0, inv_f = 0;
    int computed = 0;
    if (!ellipsoid ||
        !proj_ellipsoid_get_parameters(m.ctx, ellipsoid.get(), &m.a, &b, &computed, &inv_f))
      fail("no ellipsoid for '" + o.definition + "'");
    m.f = inv_f > 0 ? 1.0 / inv_f : 0.0;
  }

  // The operation: the best one whose grids are installed. With orthometric heights the geoid
  // grid is required; a ballpark vertical transformation (heights unchanged) is refused.
  const auto operations = [&](PROJ_GRID_AVAILABILITY_USE use) {
    PJ_OPERATION_FACTORY_CONTEXT* factory = proj_create_operation_factory_context(m.ctx, nullptr);
    proj_operation_factory_context_set_grid_availability_use(m.ctx, factory, use);
    proj_operation_factory_context_set_spatial_criterion(
        m.ctx, factory, PROJ_SPATIAL_CRITERION_PARTIAL_INTERSECTION);
    PJ_OBJ_LIST* list = proj_create_operations(m.ctx, m.source.get(), m.pivot.get(), factory);
    proj_operation_factory_context_destroy(factory);
    std::vector<PjPtr> out;
    for (int i = 0; list && i < proj_list_get_count(list); ++i)
      out.emplace_back(proj_list_get(m.ctx, list, i));
    if (list) proj_list_destroy(list);
    return out;
  };
  const auto vertical_ballpark = [&](PJ* op) {
    return Lower(proj_get_name(op)).find("ballpark vertical") != std::string::npos;
  };
  const auto grids_missing = [&](PJ* op) {
    std::vector<std::string> names;
    for (int g = 0; g < proj_coordoperation_get_grid_used_count(m.ctx, op); ++g) {
      const char *short_name = nullptr, *full_name = nullptr, *package = nullptr, *url = nullptr;
      int direct = 0, open = 0, available = 0;
      proj_coordoperation_get_grid_used(
          m.ctx, op, g, &short_name, &full_name, &package, &url, &direct, &open, &available);
      if (!available && short_name) names.emplace_back(short_name);
    }
    return names;
  };
  PjPtr chosen;
  for (auto& op : operations(PROJ_GRID_AVAILABILITY_DISCARD_OPERATION_IF_MISSING_GRID)) {
    if (!proj_coordoperation_is_instantiable(m.ctx, op.get())) continue;
    if (m.orthometric && o.geoid_grid.empty() && vertical_ballpark(op.get())) continue;
    if (!grids_missing(op.get()).empty()) continue;
    chosen = std::move(op);
    break;
  }
  if (!chosen) {
    std::set<std::string> missing;
    for (auto& op : operations(PROJ_GRID_AVAILABILITY_IGNORED))
      for (const auto& g : grids_missing(op.get())) missing.insert(g);
    std::string names;
    for (const auto& g : missing) names += (names.empty() ? "" : ", ") + g;
    fail("no conversion of '" + m.definition + "' to ellipsoidal heights: " +
         (names.empty() ? std::string("PROJ knows no operation")
                        : "the geoid grid " + names + " is not installed") +
         " (PROJ searches " + proj_info().searchpath +
         "; install it there, or name a grid file with geoid_grid:)");
  }
  m.operation_name = proj_get_name(chosen.get());
  for (int g = 0; g < proj_coordoperation_get_grid_used_count(m.ctx, chosen.get()); ++g) {
    const char *short_name = nullptr, *full_name = nullptr, *package = nullptr, *url = nullptr;
    int direct = 0, open = 0, available = 0;
    proj_coordoperation_get_grid_used(m.ctx,
                                      chosen.get(),
                                      g,
                                      &short_name,
                                      &full_name,
                                      &package,
                                      &url,
                                      &direct,
                                      &open,
                                      &available);
    m.operation_name += std::string(g == 0 ? "; grids: " : ", ") + (short_name ? short_name : "?");
  }
  m.operation.reset(proj_normalize_for_visualization(m.ctx, chosen.get()));
  if (!m.operation) fail("PROJ cannot normalise the axis order (" + m.LastError() + ")");

  if (!o.geoid_grid.empty()) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(o.geoid_grid, ec))
      fail("geoid grid '" + o.geoid_grid + "' not found");
    const std::string path = std::filesystem::absolute(o.geoid_grid).string();
    const std::string pipeline =
        "+proj=pipeline +step +proj=unitconvert +xy_in=deg +xy_out=rad +step +proj=vgridshift "
        "+grids=" +
        path + " +multiplier=1 +step +proj=unitconvert +xy_in=rad +xy_out=deg";
    m.geoid.reset(proj_create(m.ctx, pipeline.c_str()));
    if (!m.geoid)
      fail("PROJ cannot read the geoid grid '" + o.geoid_grid + "' (" + m.LastError() + ")");
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
