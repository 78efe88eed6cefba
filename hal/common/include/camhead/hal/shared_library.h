// A device library opened at run time (dlopen) instead of linked, so that
// the camhead binary starts where the library is not installed and only the
// backend that needs it fails, with a message naming the library and its
// Debian package. The renderer and `camhead bench` then run on a bare GPU
// server with nothing but a Vulkan driver and the C++ runtime (README), and
// libusb and libgpiod (both LGPL) stay separate files on the board.
//
// A backend keeps its functions in a table of pointers typed from the
// library's own header (decltype(&::libusb_init)), so a call through the
// table is checked against the header like a linked call.
//
// Thread safety: construct once (a function-local static); const members
// from any thread.
#pragma once

#include <string>
#include <utility>

namespace camhead::hal {

class SharedLibrary {
public:
  // Opens `soname` (RTLD_NOW | RTLD_LOCAL). A missing or broken library is
  // not an exception: ok() is false and error() says why.
  SharedLibrary(std::string soname, std::string debian_package);
  ~SharedLibrary(); // the handle is closed; pointers resolved from it dangle
  SharedLibrary(const SharedLibrary &) = delete;
  SharedLibrary &operator=(const SharedLibrary &) = delete;

  // Sets `function` to the library's `symbol`, or to nullptr and ok() to
  // false when the library or the symbol is missing (a wrong version).
  template <class Function> void resolve(const char *symbol, Function &function) {
    function = reinterpret_cast<Function>(find(symbol));
  }

  // True while the library is open and every resolve() found its symbol.
  [[nodiscard]] bool ok() const { return error_.empty(); }
  // "" when ok(); otherwise, for example, "libusb-1.0.so.0 (Debian package
  // libusb-1.0-0) cannot be loaded: libusb-1.0.so.0: cannot open shared
  // object file: No such file or directory".
  [[nodiscard]] const std::string &error() const { return error_; }

private:
  [[nodiscard]] void *find(const char *symbol);

  std::string soname_;
  std::string package_;
  void *handle_ = nullptr;
  std::string error_;
};

// Prints `error` and aborts: a backend called its library without checking
// that it loaded, a bug rather than a user's problem.
[[noreturn]] void abort_unloaded_library(const std::string &error);

// A library and its table of functions (a struct of pointers), resolved
// once by `resolve_all(library, functions)`. Meant to live as long as the
// process, like a linked library: a function-local static never destroyed.
template <class Functions> class FunctionTable {
public:
  template <class ResolveAll>
  FunctionTable(std::string soname, std::string debian_package, ResolveAll resolve_all)
      : library_(std::move(soname), std::move(debian_package)) {
    resolve_all(library_, functions_);
  }

  // "" when every function was found; otherwise SharedLibrary::error().
  [[nodiscard]] const std::string &error() const { return library_.error(); }
  // The table; only after error() returned "" (aborts otherwise).
  [[nodiscard]] const Functions &functions() const {
    if (!library_.ok()) {
      abort_unloaded_library(library_.error());
    }
    return functions_;
  }

private:
  SharedLibrary library_;
  Functions functions_{};
};

} // namespace camhead::hal
