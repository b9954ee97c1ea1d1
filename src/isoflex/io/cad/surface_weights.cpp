#include "isoflex/io/cad/surface_weights.hpp"

#include <fmt/format.h>

#include <IGESData_IGESModel.hxx>
#include <Interface_EntityIterator.hxx>
#include <Interface_Graph.hxx>
#include <StepData_StepModel.hxx>
#include <StepGeom_BSplineSurfaceWithKnotsAndRationalBSplineSurface.hxx>
#include <StepGeom_RationalBSplineSurface.hxx>
#include <StepShape_FaceSurface.hxx>
#include <TColStd_HArray2OfReal.hxx>
#include <TCollection_HAsciiString.hxx>
#include <XSControl_WorkSession.hxx>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "isoflex/io/cad/iges_parameters.hpp"

namespace isoflex::io::detail {

namespace {

// OCCT's IGES parser sets all weights of an entity 128 to 1 if one is below this
// (IGESGeom_ToolBSplineSurface, Precision::PConfusion()).
constexpr double kOcctSmallestIgesWeight = 1e-9;

[[noreturn]] void fail(const std::string& where, long long i, long long j, double w,
                       const char* why = "NURBS weights must be positive") {
  throw std::invalid_argument(
      fmt::format("{}: weight of control point (i, j) = ({}, {}) (i along u, from 0) is {}; {}",
                  where, i, j, w, why));
}

// IGES 128 parameters after the type: K1, K2, M1, M2, five flags, the knots in u (K1 + M1 + 2)
// and v (K2 + M2 + 2), then the weights, u fastest. Entities whose counts do not fit the data
// are left to OCCT's reader.
void check_iges(const std::filesystem::path& file) {
  for (const auto& [d, e] : iges_parameters_of_type(file, 128)) {
    const std::vector<std::string>& p = e.values;
    if (p.size() < 4) continue;
    const std::int64_t k1 = std::atoll(p[0].c_str()), k2 = std::atoll(p[1].c_str());
    const std::int64_t m1 = std::atoll(p[2].c_str()), m2 = std::atoll(p[3].c_str());
    if (k1 < 0 || k2 < 0 || m1 < 0 || m2 < 0) continue;
    const std::int64_t first = 9 + (k1 + m1 + 2) + (k2 + m2 + 2);
    const auto size = static_cast<std::int64_t>(p.size());
    if (first > size || (k1 + 1) > (size - first) / (k2 + 1)) continue;
    const std::string where = fmt::format("IGES entity 128 (D{})", d);
    for (std::int64_t j = 0; j <= k2; ++j)
      for (std::int64_t i = 0; i <= k1; ++i) {
        double w = 0;
        if (!iges_real(p[static_cast<std::size_t>(first + i + (k1 + 1) * j)], w)) continue;
        if (!(w > 0)) fail(where, i, j, w);
        if (w < kOcctSmallestIgesWeight)
          fail(where, i, j, w,
               "OpenCASCADE's IGES reader would replace all weights of the surface by 1 (weights "
               "below 1e-9)");
      }
  }
}

// "STEP #32 'name' (surface of face #20)".
std::string step_where(const XSControl_Reader& reader,
                       const opencascade::handle<StepData_StepModel>& model,
                       const opencascade::handle<StepGeom_BSplineSurface>& s) {
  std::string where = "STEP " + std::string(model->StringLabel(s)->ToCString());
  if (!s->Name().IsNull() && s->Name()->Length() > 0)
    where += fmt::format(" '{}'", s->Name()->ToCString());
  for (Interface_EntityIterator it = reader.WS()->Graph().Sharings(s); it.More(); it.Next())
    if (!opencascade::handle<StepShape_FaceSurface>::DownCast(it.Value()).IsNull())
      return where + " (surface of face " + model->StringLabel(it.Value())->ToCString() + ")";
  return where;
}

void check_step(const XSControl_Reader& reader,
                const opencascade::handle<StepData_StepModel>& model) {
  for (int n = 1; n <= model->NbEntities(); ++n) {
    const opencascade::handle<Standard_Transient>& e = model->Value(n);
    opencascade::handle<TColStd_HArray2OfReal> weights;
    if (const auto c = opencascade::handle<
            StepGeom_BSplineSurfaceWithKnotsAndRationalBSplineSurface>::DownCast(e);
        !c.IsNull())
      weights = c->WeightsData();
    else if (const auto r = opencascade::handle<StepGeom_RationalBSplineSurface>::DownCast(e);
             !r.IsNull())
      weights = r->WeightsData();
    if (weights.IsNull()) continue;
    // STEP lists the weights per u index (the outer list), 1-based in OCCT's array.
    for (int i = weights->LowerRow(); i <= weights->UpperRow(); ++i)
      for (int j = weights->LowerCol(); j <= weights->UpperCol(); ++j)
        if (const double w = weights->Value(i, j); !(w > 0))
          fail(step_where(reader, model, opencascade::handle<StepGeom_BSplineSurface>::DownCast(e)),
               i - weights->LowerRow(), j - weights->LowerCol(), w);
  }
}

}  // namespace

void check_surface_weights(const XSControl_Reader& reader, const std::filesystem::path& file) {
  const opencascade::handle<Interface_InterfaceModel> model = reader.WS()->Model();
  if (!opencascade::handle<IGESData_IGESModel>::DownCast(model).IsNull())
    check_iges(file);
  else if (const auto step = opencascade::handle<StepData_StepModel>::DownCast(model);
           !step.IsNull())
    check_step(reader, step);
}

}  // namespace isoflex::io::detail
