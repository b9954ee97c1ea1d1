#include "isoflex/io/cad/occt_messages.hpp"

#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <TCollection_AsciiString.hxx>

namespace isoflex::io::detail {

namespace {

// Keeps the first message of gravity Message_Fail; everything below the trace level is dropped
// by Message_Printer::Send before it gets here.
class FailureCollector : public Message_Printer {
 public:
  FailureCollector() { SetTraceLevel(Message_Fail); }
  const std::string& first() const { return first_; }

 protected:
  void send(const TCollection_AsciiString& text, const Message_Gravity) const override {
    if (first_.empty()) first_ = text.ToCString();
  }

 private:
  mutable std::string first_;
};

std::string one_line(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r' || c == '\t') c = ' ';
  const auto a = s.find_first_not_of(" *");
  if (a == std::string::npos) return {};
  return s.substr(a, s.find_last_not_of(" *") - a + 1);
}

}  // namespace

OcctMessageCapture::OcctMessageCapture() : collector_(new FailureCollector) {
  const opencascade::handle<Message_Messenger>& m = Message::DefaultMessenger();
  saved_ = m->Printers();
  m->ChangePrinters().Clear();
  m->AddPrinter(collector_);
}

OcctMessageCapture::~OcctMessageCapture() {
  const opencascade::handle<Message_Messenger>& m = Message::DefaultMessenger();
  m->ChangePrinters() = saved_;
}

std::string OcctMessageCapture::first_failure() const {
  return one_line(static_cast<const FailureCollector&>(*collector_).first());
}

}  // namespace isoflex::io::detail
