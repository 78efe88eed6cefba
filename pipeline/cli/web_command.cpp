// camhead web-password: sets the operator page's password (web/web_access.h).
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include <termios.h>
#include <unistd.h>

#include "cli/commands.h"
#include "web/web_access.h"
#include "web/web_server.h"

namespace camhead::cli {
namespace {

constexpr std::size_t kShortestPassword = 8;

// A line from standard input; on a terminal, asked for with `prompt` and
// not echoed.
std::string read_secret(const char *prompt) {
  const bool tty = isatty(STDIN_FILENO) != 0;
  termios before{};
  if (tty) {
    std::fprintf(stderr, "%s", prompt);
    tcgetattr(STDIN_FILENO, &before);
    termios quiet = before;
    quiet.c_lflag &= ~tcflag_t(ECHO);
    tcsetattr(STDIN_FILENO, TCSAFLUSH, &quiet);
  }
  std::string line;
  std::getline(std::cin, line);
  if (tty) {
    tcsetattr(STDIN_FILENO, TCSAFLUSH, &before);
    std::fprintf(stderr, "\n");
  }
  return line;
}

int set_password(const std::string &file) {
  const std::string password = read_secret("operator page password: ");
  if (password.size() < kShortestPassword) {
    std::fprintf(stderr,
                 "camhead web-password: the password has %zu characters; give at least %zu "
                 "(nothing written)\n",
                 password.size(), kShortestPassword);
    return 2;
  }
  if (isatty(STDIN_FILENO) != 0 && read_secret("again: ") != password) {
    std::fprintf(stderr, "camhead web-password: the two differ (nothing written)\n");
    return 2;
  }
  try {
    pipeline::web::write_password_file(file, pipeline::web::hash_password(password));
  } catch (const std::exception &e) {
    std::fprintf(stderr, "camhead web-password: %s\n", e.what());
    return 4;
  }
  std::fprintf(stderr, "camhead web-password: %s holds the password's hash (mode 0600)\n",
               file.c_str());
  return 0;
}

} // namespace

void add_web_command(CLI::App &app) {
  auto file = std::make_shared<std::string>();
  CLI::App *cmd = app.add_subcommand(
      "web-password",
      "Sets the operator page's password (`camhead run --http ADDR:PORT --http-password\n"
      "FILE`, or a board's \"http\"): reads it from standard input (twice, unechoed, on a\n"
      "terminal; at least 8 characters) and writes its yescrypt hash, as /etc/shadow\n"
      "keeps one, to FILE with mode 0600, replacing FILE whole. Browsers ask for it once\n"
      "(any user name). There is no default password: a page that other machines reach\n"
      "is served only with one.\n"
      "Example:\n"
      "  camhead web-password /etc/camhead/web-password\n"
      "Exit status: 0 written; 2 too short or not the same twice; 4 FILE not written.");
  cmd->add_option("FILE", *file, "The password file")->required()->check(path_text());
  cmd->callback([file] { set_exit_code(set_password(*file)); });
}

} // namespace camhead::cli
