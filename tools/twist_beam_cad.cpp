// Writes examples/kl_twist_beam/twist_beam.stp: a simplified twist-beam cross member (IGA-thesis
// §6.4.2.4; the thesis' 5-patch geometry, Fig. 6.25a, is not in its text, so this one is ours) as
// five untrimmed B-spline faces of one STEP file, the way a CAD system hands a multi-patch part
// over: a lipped channel of length L along x whose section is
//
//     lip ┐                 ┌ lip        the web (patch 0) in the plane z = 0, |y| ≤ w/2;
//         │ flange   flange │            the flanges (1, 2) rising outwards at `flare` from the
//          \               /             vertical to the height h; the lips (3, 4) turned
//           \_____________/              horizontally outwards by `lip`.
//                 web
//
// Every face is a bilinear patch (degree 1 × 1), u along x from 0 to L, v across the section
// from the web outwards; neighbours share their long edges exactly (the same end points), so
// isoflex joins them (kl_interfaces) after raising the degree. Millimetres.
//
//   build/bench/twist_beam_cad OUT.stp
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRep_Builder.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Message_PrinterOStream.hxx>
#include <STEPControl_Writer.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <TopoDS_Compound.hxx>
#include <cmath>
#include <cstdio>

namespace {

constexpr double L = 1000.0, w = 80.0, h = 60.0, lip = 20.0;
const double flare = 15.0 * std::acos(-1.0) / 180.0;  // the flanges' tilt from the vertical

// The bilinear face with corners a (u = 0, v = 0), b (u = 0, v = 1) translated along x by L.
TopoDS_Face face(const gp_Pnt& a, const gp_Pnt& b) {
  TColgp_Array2OfPnt poles(1, 2, 1, 2);
  poles(1, 1) = a;
  poles(1, 2) = b;
  poles(2, 1) = gp_Pnt(a.X() + L, a.Y(), a.Z());
  poles(2, 2) = gp_Pnt(b.X() + L, b.Y(), b.Z());
  TColStd_Array1OfReal knots(1, 2);
  knots(1) = 0.0;
  knots(2) = 1.0;
  TColStd_Array1OfInteger mults(1, 2);
  mults(1) = mults(2) = 2;
  Handle(Geom_BSplineSurface) s = new Geom_BSplineSurface(poles, knots, knots, mults, mults, 1, 1);
  return BRepBuilderAPI_MakeFace(s, 1e-7);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: twist_beam_cad OUT.stp\n");
    return 2;
  }
  // Section points for y ≥ 0 (mirrored for y < 0): web edge, flange top, lip end.
  const double yw = 0.5 * w, yf = yw + h * std::tan(flare);
  const auto section = [&](double side, int k) {
    const double y[] = {0.0, yw, yf, yf + lip}, z[] = {0.0, 0.0, h, h};
    return gp_Pnt(0.0, side * y[k], z[k]);
  };
  BRep_Builder builder;
  TopoDS_Compound part;
  builder.MakeCompound(part);
  // Patch 0 the web from y = −w/2 to w/2 (v across), then for each side the flange and the lip,
  // each v from the inner edge outwards: 1 = flange −y, 2 = flange +y, 3 = lip −y, 4 = lip +y.
  builder.Add(part, face(section(-1.0, 1), section(1.0, 1)));
  for (int k = 1; k <= 2; ++k)
    for (double side : {-1.0, 1.0}) builder.Add(part, face(section(side, k), section(side, k + 1)));
  // The writer's transfer statistics are not this tool's output.
  Message::DefaultMessenger()->RemovePrinters(STANDARD_TYPE(Message_PrinterOStream));
  STEPControl_Writer writer;
  if (writer.Transfer(part, STEPControl_AsIs) != IFSelect_RetDone ||
      writer.Write(argv[1]) != IFSelect_RetDone) {
    std::fprintf(stderr, "twist_beam_cad: cannot write %s\n", argv[1]);
    return 1;
  }
  std::printf("wrote %s: 5 faces, L = %g, web %g, flanges %g at %g deg, lips %g (mm)\n", argv[1], L,
              w, h, flare * 180.0 / std::acos(-1.0), lip);
  return 0;
}
