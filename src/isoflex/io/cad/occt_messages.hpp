#pragma once
// Takes over OpenCASCADE's default messenger while a CAD file is read: nothing is printed
// (OCCT prints transfer statistics and parse errors on stdout), failure messages are kept for the
// error message instead, and the messenger's own printers are put back on destruction, so
// reading leaves OCCT's process-wide messenger as it found it. Internal to io/cad; not
// thread-safe (neither is OCCT's messenger).
#include <Message_Printer.hxx>
#include <Message_SequenceOfPrinters.hxx>
#include <string>

namespace isoflex::io::detail {

class OcctMessageCapture {
 public:
  OcctMessageCapture();
  ~OcctMessageCapture();
  OcctMessageCapture(const OcctMessageCapture&) = delete;
  OcctMessageCapture& operator=(const OcctMessageCapture&) = delete;

  // The first failure message OCCT sent, as one line without OCCT's "****" framing ("" if none).
  std::string first_failure() const;

 private:
  Message_SequenceOfPrinters saved_;
  opencascade::handle<Message_Printer> collector_;
};

}  // namespace isoflex::io::detail
