#pragma once
// Runs one of the project's executables as a child process, with its stderr captured to a file, so
// that tests can check exit codes, messages and signal handling the way a user would see them.
// Its stdout goes to the same file, or to a file of its own for a program whose stdout is data
// (JSON) that its log lines must not be mixed into.
//
// In a cross build the tests run under the build's emulator (ctest puts
// CMAKE_CROSSCOMPILING_EMULATOR in front of them), and so do the project's programs they start: a
// program of this build (one under SURROUNDD_BINARY_DIR) is started as SURROUNDD_PROGRAM_LAUNCHER
// (the emulator's command, a list of string literals; empty in a native build) followed by its own
// arguments. Both are set by tests/support/CMakeLists.txt (surroundd_test_process).

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

namespace surroundd::testing {

class ChildProcess {
 public:
  // `environment`: NAME=VALUE entries added to the child's environment.
  ChildProcess(std::vector<std::string> arguments, std::filesystem::path stderrFile,
               std::vector<std::string> environment = {}, std::filesystem::path stdoutFile = {})
      : stderrFile_(std::move(stderrFile)), stdoutFile_(std::move(stdoutFile)) {
    arguments = launched(std::move(arguments));
    std::vector<char*> argv;
    for (auto& argument : arguments) argv.push_back(argument.data());
    argv.push_back(nullptr);
    pid_ = ::fork();
    if (pid_ == 0) {
      const int fd = ::open(stderrFile_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      ::dup2(fd, STDERR_FILENO);
      if (stdoutFile_.empty()) {
        ::dup2(fd, STDOUT_FILENO);
      } else {
        ::dup2(::open(stdoutFile_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644), STDOUT_FILENO);
      }
      for (auto& entry : environment) ::putenv(entry.data());
      ::execv(argv[0], argv.data());
      ::_exit(127);
    }
  }
  ~ChildProcess() {
    if (pid_ > 0 && !exited_) {
      ::kill(pid_, SIGKILL);
      wait();
    }
  }
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  void signal(int number) const { ::kill(pid_, number); }

  // Whether it has not exited yet (if it has, its status is collected and wait() is not needed).
  bool running() {
    if (exited_) return false;
    if (::waitpid(pid_, &status_, WNOHANG) == 0) return true;
    exited_ = true;
    return false;
  }

  // Exit status, or 128 + signal number when it was killed.
  int wait() {
    if (!exited_) ::waitpid(pid_, &status_, 0);
    exited_ = true;
    return WIFEXITED(status_) ? WEXITSTATUS(status_) : 128 + WTERMSIG(status_);
  }

  // What it wrote to stderr (and stdout, unless that has its own file).
  std::string output() const { return contents(stderrFile_); }
  // What it wrote to stdout, when that has its own file.
  std::string standardOutput() const { return contents(stdoutFile_); }

 private:
  // `arguments` with the emulator in front where they start a program of this build.
  static std::vector<std::string> launched(std::vector<std::string> arguments) {
    const std::vector<std::string> launcher{SURROUNDD_PROGRAM_LAUNCHER};
    const std::string build = std::string(SURROUNDD_BINARY_DIR) + "/";
    if (launcher.empty() || arguments.empty() || !arguments.front().starts_with(build)) {
      return arguments;
    }
    arguments.insert(arguments.begin(), launcher.begin(), launcher.end());
    return arguments;
  }

  static std::string contents(const std::filesystem::path& path) {
    std::ifstream file(path);
    std::stringstream text;
    text << file.rdbuf();
    return text.str();
  }

  std::filesystem::path stderrFile_;
  std::filesystem::path stdoutFile_;
  pid_t pid_ = -1;
  bool exited_ = false;
  int status_ = 0;  // waitpid's, once it has exited
};

}  // namespace surroundd::testing
