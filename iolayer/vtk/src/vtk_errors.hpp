#pragma once
// Collects the first error a VTK object reports, so the caller can throw it as a FormatError
// instead of VTK printing it to the terminal.
#include <vtkCommand.h>
#include <vtkObject.h>

#include <string>

namespace basalt::io::detail {

/// VTK's messages end in blank lines; keep the text only.
inline std::string trimmed(const char* t) {
  std::string s = t;
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  return s;
}

class VtkErrorCatcher : public vtkCommand {
 public:
  static VtkErrorCatcher* New() { return new VtkErrorCatcher; }
  void Execute(vtkObject* /*caller*/, unsigned long /*event*/, void* data) override {
    if (message.empty() && data != nullptr) message = trimmed(static_cast<const char*>(data));
    ++count;
  }
  /// Listens for errors (and warnings: VTK's XML readers report unreadable data as warnings too).
  void watch(vtkObject* obj) {
    obj->AddObserver(vtkCommand::ErrorEvent, this);
    obj->AddObserver(vtkCommand::WarningEvent, this);
  }
  std::string message;
  int count = 0;
};

}  // namespace basalt::io::detail

#include <vtkLogger.h>
#include <vtkOutputWindow.h>
#include <vtkSmartPointer.h>

namespace basalt::io::detail {

/// While alive, VTK's messages (e.g. the XML parser's, which no observer sees) are collected here
/// instead of being printed; the first error becomes part of the FormatError the caller throws.
class CapturingOutputWindow : public vtkOutputWindow {
 public:
  static CapturingOutputWindow* New() { return new CapturingOutputWindow; }
  void DisplayText(const char* t) override { keep(t); }
  void DisplayErrorText(const char* t) override { keep(t); }
  void DisplayWarningText(const char* t) override { keep(t); }
  void DisplayGenericWarningText(const char* t) override { keep(t); }
  void DisplayDebugText(const char*) override {}
  std::string first;

 private:
  void keep(const char* t) {
    if (first.empty() && t != nullptr) first = trimmed(t);
  }
};

class ScopedVtkMessages {
 public:
  ScopedVtkMessages()
      : previous_(vtkOutputWindow::GetInstance()), window_(vtkSmartPointer<CapturingOutputWindow>::New()) {
    vtkOutputWindow::SetInstance(window_);
    vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);  // VTK also logs errors to stderr itself
  }
  ~ScopedVtkMessages() {
    vtkOutputWindow::SetInstance(previous_);
    vtkLogger::SetStderrVerbosity(verbosity_);
  }
  ScopedVtkMessages(const ScopedVtkMessages&) = delete;
  ScopedVtkMessages& operator=(const ScopedVtkMessages&) = delete;
  const std::string& first() const { return window_->first; }

 private:
  vtkLogger::Verbosity verbosity_ = vtkLogger::GetCurrentVerbosityCutoff();
  vtkSmartPointer<vtkOutputWindow> previous_;
  vtkSmartPointer<CapturingOutputWindow> window_;
};

}  // namespace basalt::io::detail
