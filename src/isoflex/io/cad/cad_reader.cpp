#include <IFSelect_ReturnStatus.hxx>
#include <IGESControl_Reader.hxx>
#include <IGESData_GlobalSection.hxx>
#include <IGESData_IGESEntity.hxx>
#include <IGESData_IGESModel.hxx>
#include <IGESData_NameEntity.hxx>
#include <Interface_EntityIterator.hxx>
#include <Interface_Graph.hxx>
#include <Interface_InterfaceModel.hxx>
#include <STEPControl_Reader.hxx>
#include <Standard_Failure.hxx>
#include <StepData_StepModel.hxx>
#include <StepGeom_Surface.hxx>
#include <StepRepr_RepresentationItem.hxx>
#include <StepShape_FaceSurface.hxx>
#include <TColStd_SequenceOfAsciiString.hxx>
#include <TCollection_HAsciiString.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_MapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Face.hxx>
#include <XSControl_TransferReader.hxx>
#include <XSControl_WorkSession.hxx>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <new>
#include <optional>
#include <stdexcept>
#include <string>

#include "isoflex/io/cad/cad_plugin.hpp"
#include "isoflex/io/cad/face_trimming.hpp"
#include "isoflex/io/cad/occt_messages.hpp"
#include "isoflex/io/cad/occt_nurbs.hpp"
#include "isoflex/io/cad/surface_weights.hpp"

namespace isoflex::io {

namespace {

// What the reader is doing, kept for error messages and passed on to the caller's callback.
class Stages {
 public:
  Stages(CadStageFn fn, void* context) : fn_(fn), context_(context) {}
  void enter(std::string stage) {
    current_ = std::move(stage);
    if (fn_) fn_(context_, current_.c_str());
  }
  const std::string& current() const { return current_; }

 private:
  CadStageFn fn_;
  void* context_;
  std::string current_ = "opening the file";
};

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::string trim(const std::string& s) {
  const auto a = s.find_first_not_of(" \t");
  if (a == std::string::npos) return {};
  return s.substr(a, s.find_last_not_of(" \t") - a + 1);
}

std::string text(const opencascade::handle<TCollection_HAsciiString>& s) {
  return s.IsNull() ? std::string() : trim(s->ToCString());
}

std::optional<CadFormat> format_from_extension(const std::filesystem::path& file) {
  const std::string ext = lower(file.extension().string());
  if (ext == ".igs" || ext == ".iges") return CadFormat::iges;
  if (ext == ".stp" || ext == ".step") return CadFormat::step;
  return std::nullopt;
}

// IGES global section, parameter 14 (unit flag) with 15 (unit name) for flag 3.
std::string iges_unit_name(const IGESData_GlobalSection& gs) {
  switch (gs.UnitFlag()) {
    case 1:
      return "inch";
    case 2:
      return "millimetre";
    case 4:
      return "foot";
    case 5:
      return "mile";
    case 6:
      return "metre";
    case 7:
      return "kilometre";
    case 8:
      return "mil";
    case 9:
      return "micrometre";
    case 10:
      return "centimetre";
    case 11:
      return "microinch";
    default:
      return lower(text(gs.UnitName()));
  }
}

// OCCT scales coordinates from the file's unit to its own (millimetres). Making the file's unit
// OCCT's unit keeps the numbers of the file.
std::string keep_iges_units(IGESControl_Reader& reader) {
  const opencascade::handle<IGESData_IGESModel> model = reader.IGESModel();
  IGESData_GlobalSection gs = model->GlobalSection();
  const double unit_in_mm = gs.UnitValue();  // relative to the cascade unit (1 = mm) still set
  if (unit_in_mm > 0 && std::isfinite(unit_in_mm)) {
    gs.SetCascadeUnit(unit_in_mm);
    model->SetGlobalSection(gs);
    return iges_unit_name(gs);
  }
  return "millimetre (converted from an unknown unit)";
}

// Millimetres per unit for the SI length units (any prefix) and the common imperial ones; NaN
// for names OCCT reports that are not known here.
double step_unit_in_mm(const std::string& name) {
  const std::string n = lower(trim(name));
  if (n == "inch") return 25.4;
  if (n == "foot") return 304.8;
  for (const char* metre : {"metre", "meter"}) {
    const std::string m = metre;
    if (n.size() < m.size() || n.compare(n.size() - m.size(), m.size(), m) != 0) continue;
    const std::string prefix = n.substr(0, n.size() - m.size());
    if (prefix.empty()) return 1e3;
    if (prefix == "kilo") return 1e6;
    if (prefix == "deci") return 1e2;
    if (prefix == "centi") return 1e1;
    if (prefix == "milli") return 1.0;
    if (prefix == "micro") return 1e-3;
    if (prefix == "nano") return 1e-6;
  }
  return std::nan("");
}

std::string keep_step_units(STEPControl_Reader& reader) {
  TColStd_SequenceOfAsciiString lengths, angles, solid_angles;
  reader.FileUnits(lengths, angles, solid_angles);
  std::string name;
  for (int k = 1; k <= lengths.Length(); ++k) {
    const std::string n = trim(lengths(k).ToCString());
    if (n.empty()) continue;
    if (!name.empty() && n != name) return "millimetre (converted from several units)";
    name = n;
  }
  if (name.empty()) return "";
  const double mm = step_unit_in_mm(name);
  if (!std::isfinite(mm)) return "millimetre (converted from " + name + ")";
  reader.SetSystemLengthUnit(mm);
  return lower(name);
}

// The entity a face came from, or null.
opencascade::handle<Standard_Transient> source_entity(const XSControl_Reader& reader,
                                                      const TopoDS_Face& face) {
  const opencascade::handle<XSControl_TransferReader> tr = reader.WS()->TransferReader();
  if (tr.IsNull()) return nullptr;
  opencascade::handle<Standard_Transient> ent = tr->EntityFromShapeResult(face, 1);
  if (ent.IsNull()) ent = tr->EntityFromShapeResult(face, 3);
  return ent;
}

// The name property (406 form 15) of an IGES entity, else its entity label with a non-zero
// subscript, e.g. "WEB" or "WEB(2)" (OCCT's NameValue appends even a subscript 0).
std::string iges_name(const opencascade::handle<IGESData_IGESEntity>& e) {
  if (e.IsNull()) return {};
  for (Interface_EntityIterator it = e->Properties(); it.More(); it.Next())
    if (const auto n = opencascade::handle<IGESData_NameEntity>::DownCast(it.Value()); !n.IsNull())
      if (auto s = text(n->Value()); !s.empty()) return s;
  if (!e->HasShortLabel()) return {};
  std::string s = text(e->ShortLabel());
  if (!s.empty() && e->HasSubScriptNumber() && e->SubScriptNumber() != 0)
    s += "(" + std::to_string(e->SubScriptNumber()) + ")";
  return s;
}

std::string step_name(const opencascade::handle<Standard_Transient>& ent) {
  const auto item = opencascade::handle<StepRepr_RepresentationItem>::DownCast(ent);
  return item.IsNull() ? std::string() : text(item->Name());
}

// The name or label the file gives a face: the entity's own, else that of the surface it
// refers to (STEP) or of an entity referring to it (IGES: the 144 around a 128).
std::string entity_name(const XSControl_Reader& reader,
                        const opencascade::handle<Standard_Transient>& ent) {
  if (ent.IsNull()) return {};
  if (const auto ig = opencascade::handle<IGESData_IGESEntity>::DownCast(ent); !ig.IsNull()) {
    if (auto n = iges_name(ig); !n.empty()) return n;
    for (Interface_EntityIterator it = reader.WS()->Graph().Sharings(ent); it.More(); it.Next())
      if (auto n = iges_name(opencascade::handle<IGESData_IGESEntity>::DownCast(it.Value()));
          !n.empty())
        return n;
    return {};
  }
  if (auto n = step_name(ent); !n.empty()) return n;
  if (const auto f = opencascade::handle<StepShape_FaceSurface>::DownCast(ent); !f.IsNull())
    return step_name(f->FaceGeometry());
  return {};
}

std::string entity_label(const XSControl_Reader& reader,
                         const opencascade::handle<Standard_Transient>& ent) {
  if (ent.IsNull()) return {};
  if (const auto ig = opencascade::handle<IGESData_IGESEntity>::DownCast(ent); !ig.IsNull()) {
    const auto model = opencascade::handle<IGESData_IGESModel>::DownCast(reader.WS()->Model());
    std::string s = "IGES entity " + std::to_string(ig->TypeNumber());
    if (!model.IsNull()) s += " (D" + std::to_string(model->DNum(ig)) + ")";
    return s;
  }
  if (const auto model = opencascade::handle<StepData_StepModel>::DownCast(reader.WS()->Model());
      !model.IsNull())
    return "STEP " + text(model->StringLabel(ent));
  return {};
}

std::string failure_text(const Standard_Failure& e) {
  const std::string what = trim(e.GetMessageString() ? e.GetMessageString() : "");
  return std::string(e.DynamicType()->Name()) + (what.empty() ? "" : ": " + what);
}

CadPatch make_patch(const XSControl_Reader& reader, const TopoDS_Face& face, int index) {
  CadPatch p;
  p.index = index;
  const opencascade::handle<Standard_Transient> ent = source_entity(reader, face);
  p.entity = entity_label(reader, ent);
  p.name = entity_name(reader, ent);
  if (p.name.empty()) p.name = "patch " + std::to_string(index);
  const std::string where =
      "face " + std::to_string(index) + (p.entity.empty() ? "" : " (" + p.entity + ")");

  detail::FaceSurface fs;
  try {
    fs = detail::face_surface(face);
  } catch (const Standard_Failure& e) {
    throw std::invalid_argument(where + ": its surface has no exact B-spline form (" +
                                failure_text(e) + ")");
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(where + ": " + e.what());
  }
  try {
    p.surface = detail::to_nurbs(fs.bspline);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(where + ": " + fs.type + " surface not supported: " + e.what());
  }
  p.surface_type = fs.type;
  p.converted = fs.converted;
  p.reversed_orientation = face.Orientation() == TopAbs_REVERSED;
  p.trimmed = !detail::has_natural_boundary(face, fs.u0, fs.u1, fs.v0, fs.v1);
  return p;
}

// Parses the file into the reader's model and checks what OCCT's transfer would hide; throws
// CadError with OCCT's first failure message.
void parse(XSControl_Reader& reader, const CadModel& model,
           const detail::OcctMessageCapture& messages, Stages& stages) {
  const std::string name = model.file.string();
  const std::string format = to_string(model.format);
  stages.enter("parsing the " + format + " file");
  if (reader.ReadFile(name.c_str()) != IFSelect_RetDone) {
    const std::string why = messages.first_failure();
    throw CadError(name, "cannot be read as " + format + ": " +
                             (why.empty() ? "not a valid file or a syntax error" : why));
  }
  if (reader.Model().IsNull() || reader.Model()->NbEntities() == 0)
    throw CadError(
        name, "cannot be read as " + format + ": no entities found (not an " + format + " file?)");
  stages.enter("checking the weights of the " + format + " B-spline surfaces");
  detail::check_surface_weights(reader, model.file);
}

// Transfers every root and makes one patch per distinct face, in the order of the file.
void transfer_faces(XSControl_Reader& reader, CadModel& model, Stages& stages) {
  stages.enter(std::string("translating the ") + to_string(model.format) + " entities into shapes");
  reader.TransferRoots();
  const TopoDS_Shape shape = reader.OneShape();
  TopTools_MapOfShape seen;
  for (TopExp_Explorer ex(shape, TopAbs_FACE); ex.More(); ex.Next()) {
    if (!seen.Add(ex.Current())) continue;
    const int index = static_cast<int>(model.patches.size());
    stages.enter("converting face " + std::to_string(index) + " to a NURBS patch");
    model.patches.push_back(make_patch(reader, TopoDS::Face(ex.Current()), index));
  }
}

}  // namespace

CadModel read_cad_occt(const std::filesystem::path& file, CadStageFn stage, void* context) {
  const std::string name = file.string();
  Stages stages(stage, context);
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) throw CadError(name, "no such file");
  if (std::filesystem::is_directory(file, ec)) throw CadError(name, "is a directory, not a file");
  const auto format = format_from_extension(file);
  if (!format)
    throw CadError(name, "unknown extension '" + file.extension().string() +
                             "' (expected .igs, .iges, .stp or .step)");

  CadModel model;
  model.file = file;
  model.format = *format;
  const detail::OcctMessageCapture messages;
  try {
    if (*format == CadFormat::iges) {
      IGESControl_Reader reader;
      parse(reader, model, messages, stages);
      model.length_unit = keep_iges_units(reader);
      transfer_faces(reader, model, stages);
    } else {
      STEPControl_Reader reader;
      parse(reader, model, messages, stages);
      model.length_unit = keep_step_units(reader);
      transfer_faces(reader, model, stages);
    }
  } catch (const CadError&) {
    throw;
  } catch (const std::invalid_argument& e) {
    throw CadError(name, e.what());
  } catch (const std::bad_alloc&) {
    // Bare "std::bad_alloc" says neither what nor where: a count in the file far too large.
    throw CadError(name, "out of memory (std::bad_alloc) while " + stages.current() +
                             ": a count in the file is probably far too large");
  } catch (const Standard_Failure& e) {
    throw CadError(name, "OpenCASCADE failed (" + failure_text(e) + ") while " + stages.current());
  } catch (const std::exception& e) {
    throw CadError(name, std::string(e.what()) + " while " + stages.current());
  }
  if (model.patches.empty())
    throw CadError(name,
                   std::string("no surfaces: the ") + to_string(*format) + " file holds no faces");
  return model;
}

}  // namespace isoflex::io
