// Running the built sigmafem program from a test: its exit code and everything it printed.
#pragma once

#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace sigmafem::test {

struct CommandRun {
  int exit_code = -1;
  std::string output;   // stdout and stderr together
};

inline CommandRun run_sigmafem_command(const std::string& command_line) {
  const std::string command = command_line + " 2>&1";
  CommandRun run;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return run;
  char buffer[4096];
  while (std::fgets(buffer, sizeof buffer, pipe)) run.output += buffer;
  const int status = pclose(pipe);
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

// `sigmafem ARGUMENTS`.
inline CommandRun run_sigmafem(const std::string& arguments) {
  return run_sigmafem_command(std::string(SIGMAFEM_BINARY) + " " + arguments);
}

// The same with environment assignments ("NAME=value ...") before the program.
inline CommandRun run_sigmafem_with_env(const std::string& environment, const std::string& arguments) {
  return run_sigmafem_command(environment + " " + std::string(SIGMAFEM_BINARY) + " " + arguments);
}

}  // namespace sigmafem::test
