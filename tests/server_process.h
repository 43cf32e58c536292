// A server binary a test runs as a child process (tests/services_test.cc,
// tests/hostile_input_test.cc), on a port the kernel chose.
//
// The first start passes --port=0 and the test reads the port the child bound
// from the line it prints once it listens ("index listening on port 41234",
// common/rpc/server_main.cc; "meshseek serving on 127.0.0.1:41234"). A restart
// after Kill() binds that same port again, so the addresses other servers and
// clients hold stay right.
//
// Why not choose a free port for the child: a port found free and released
// before the child binds it (fork, exec, sanitizer start-up: a few hundred
// milliseconds) can be handed meanwhile to another test's server, CTest
// running cases side by side; and while gRPC servers bound with SO_REUSEPORT
// both listened, each answering some of the calls. (A services case under
// ThreadSanitizer in CI at 8393e9d saw its coordinator refuse the first
// CreateCollection 0.6 s after start; servers now refuse a taken port,
// common/rpc/server.cc.) What is left is a restart's port, free while its
// server is down; a clash there fails the restart loudly.
#ifndef MESHSEEK_TESTS_SERVER_PROCESS_H_
#define MESHSEEK_TESTS_SERVER_PROCESS_H_

#include <sys/types.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "absl/time/time.h"

namespace meshseek {

class ServerProcess {
 public:
  /// `argv`: the binary's path and its flags, --port aside. `log`: the file
  /// its stdout and stderr are appended to. `port_marker`: the text it
  /// prints right before its port.
  ServerProcess(std::vector<std::string> argv,
                std::string log,
                std::string port_marker = " listening on port ");
  ~ServerProcess();  // SIGKILL
  ServerProcess(const ServerProcess&) = delete;
  ServerProcess& operator=(const ServerProcess&) = delete;

  /// Starts it: on port 0 until a start has printed its port, then on that port.
  void Start();
  /// Flags of the next Start.
  void AddArgs(const std::vector<std::string>& args);
  /// Sends `signal` and reaps the process.
  void Kill(int signal);
  /// Waits, by the clock, until the process has printed its port and its
  /// health service says SERVING; false (the log's end on stderr) when it
  /// exits first or `within` passes.
  bool WaitServing(absl::Duration within = absl::Seconds(90));
  /// Waits up to `within` for the process to exit by itself: its exit code,
  /// 128 when a signal ended it, -1 if it is still running.
  int WaitExit(absl::Duration within);

  /// 0 until a WaitServing has read it.
  int port() const { return port_; }
  pid_t pid() const { return pid_; }
  const std::string& log() const { return log_; }

 private:
  std::string ReadLog(std::uintmax_t from) const;
  void ReadPort();            // from the log, past what earlier starts wrote
  std::optional<int> Reap();  // its exit code (128: a signal) if it has ended

  std::vector<std::string> argv_;
  std::string log_;
  std::string port_marker_;
  std::uintmax_t log_start_ = 0;  // the log's size when the last Start ran
  int port_ = 0;
  pid_t pid_ = -1;
};

}  // namespace meshseek

#endif  // MESHSEEK_TESTS_SERVER_PROCESS_H_
