#include "tests/server_process.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <thread>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "grpc/health/v1/health.grpc.pb.h"
#include "grpcpp/grpcpp.h"

namespace meshseek {

ServerProcess::ServerProcess(std::vector<std::string> argv, std::string log, std::string port_marker)
    : argv_(std::move(argv)), log_(std::move(log)), port_marker_(std::move(port_marker)) {
  Start();
}

ServerProcess::~ServerProcess() { Kill(SIGKILL); }

void ServerProcess::AddArgs(const std::vector<std::string>& args) {
  argv_.insert(argv_.end(), args.begin(), args.end());
}

void ServerProcess::Start() {
  std::error_code error;
  const std::uintmax_t size = std::filesystem::file_size(log_, error);
  log_start_ = error ? 0 : size;
  std::vector<std::string> argv = argv_;
  argv.push_back(absl::StrCat("--port=", port_));
  pid_ = fork();
  if (pid_ == 0) {
    const int fd = ::open(log_.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    dup2(fd, 1);
    dup2(fd, 2);
    std::vector<char*> args;
    for (std::string& a : argv) args.push_back(a.data());
    args.push_back(nullptr);
    execv(args[0], args.data());
    _exit(127);
  }
}

void ServerProcess::Kill(int signal) {
  if (pid_ <= 0) return;
  ::kill(pid_, signal);
  waitpid(pid_, nullptr, 0);
  pid_ = -1;
}

std::string ServerProcess::ReadLog(std::uintmax_t from) const {
  std::ifstream in(log_);
  in.seekg(static_cast<std::streamoff>(from));
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void ServerProcess::ReadPort() {
  const std::string text = ReadLog(log_start_);
  const std::size_t at = text.find(port_marker_);
  if (at == std::string::npos) return;
  const std::size_t begin = at + port_marker_.size();
  std::size_t end = begin;
  while (end < text.size() && text[end] >= '0' && text[end] <= '9') ++end;
  // Nothing after the digits yet: the number may be cut short.
  if (end == text.size()) return;
  int port = 0;
  if (absl::SimpleAtoi(text.substr(begin, end - begin), &port)) port_ = port;
}

std::optional<int> ServerProcess::Reap() {
  int status = 0;
  if (pid_ <= 0 || waitpid(pid_, &status, WNOHANG) != pid_) return std::nullopt;
  pid_ = -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

bool ServerProcess::WaitServing(absl::Duration within) {
  // By the clock, not by tries: a refused connection fails at once, and a
  // restart after kill -9 under TSan on a loaded machine takes seconds.
  const absl::Time end = absl::Now() + within;
  std::unique_ptr<grpc::health::v1::Health::Stub> health;
  while (absl::Now() < end && pid_ > 0 && !Reap().has_value()) {
    if (port_ == 0) ReadPort();
    if (port_ != 0 && health == nullptr) {
      health = grpc::health::v1::Health::NewStub(grpc::CreateChannel(
          absl::StrCat("127.0.0.1:", port_), grpc::InsecureChannelCredentials()));
    }
    if (health != nullptr) {
      grpc::ClientContext context;
      context.set_deadline(std::chrono::system_clock::now() + std::chrono::milliseconds(500));
      grpc::health::v1::HealthCheckRequest request;
      grpc::health::v1::HealthCheckResponse response;
      if (health->Check(&context, request, &response).ok() &&
          response.status() == grpc::health::v1::HealthCheckResponse::SERVING) {
        return true;
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  const std::string text = ReadLog(0);
  std::cerr << argv_[0] << (pid_ <= 0 ? " exited" : " is not serving") << "; the end of " << log_
            << ":\n"
            << text.substr(text.size() > 2000 ? text.size() - 2000 : 0) << "\n";
  return false;
}

int ServerProcess::WaitExit(absl::Duration within) {
  const absl::Time end = absl::Now() + within;
  while (pid_ > 0 && absl::Now() < end) {
    if (const std::optional<int> code = Reap()) return *code;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return -1;
}

}  // namespace meshseek
