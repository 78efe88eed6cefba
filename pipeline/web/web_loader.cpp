// Finds and opens libcamhead_web.so (web_server.h), as marker_loader.cpp
// opens the marker module: $CAMHEAD_WEB_MODULE, beside the executable, the
// install's lib folder, then the library path. No libevent header here.
#include <string>

#include "camhead/hal/module_loader.h"
#include "web_module_abi.h"
#include "web_server.h"

namespace camhead::pipeline::web {
namespace {

constexpr const char *kModuleName = CAMHEAD_WEB_MODULE_NAME;
// The Debian packages whose libraries the module needs at run time.
constexpr const char *kPackages = "libevent-2.1-7 and libturbojpeg0";

// Opened once and never closed: its server threads run its code until the end.
web_module::Module &module() {
  static hal::ModuleOnce<web_module::Module> once;
  const hal::ModuleSearch search =
      hal::module_search("CAMHEAD_WEB_MODULE", kModuleName, CAMHEAD_WEB_MODULE_RELDIR);
  hal::LoadedModule<web_module::Module> loaded;
  if (web_module::Module *opened = once.get(
          [&] {
            return hal::load_module<web_module::Module>(search, kModuleName, kPackages,
                                                        web_module::kFactorySymbol,
                                                        web_module::kAbiVersion, "its web module");
          },
          loaded))
    return *opened;
  const std::string &last_error = loaded.error;
  if (!last_error.empty())
    throw WebError(last_error);
  throw WebError(std::string(kModuleName) + " is not in " + search.searched +
                 ": camhead builds it where libevent-dev and libturbojpeg0-dev are installed "
                 "(cmake/bootstrap.sh installs them), and it needs the Debian packages " +
                 kPackages + " to run");
}

// The module, or WebError saying the operator page cannot be served and why.
web_module::Module &page_module() {
  try {
    return module();
  } catch (const WebError &e) {
    throw WebError(std::string("operator page: ") + e.what());
  }
}

} // namespace

const char *web_module_name() {
  return kModuleName;
}

std::string web_module_problem() {
  try {
    (void)module();
    return {};
  } catch (const WebError &e) {
    return e.what();
  }
}

std::unique_ptr<web_module::Server> start_web_server(const web_module::ServerConfig &config,
                                                     web_module::Host &host) {
  std::string error;
  std::unique_ptr<web_module::Server> server = page_module().start(config, host, error);
  if (!server)
    throw WebError("operator page: " + error);
  return server;
}

std::string hash_password(const std::string &password) {
  std::string hash, error;
  if (!page_module().hash_password(password, hash, error))
    throw WebError("operator page: " + error);
  return hash;
}

} // namespace camhead::pipeline::web
