// A free TCP port on the loopback interface, for tests and benchmarks that
// start server processes (which need the port before they start). The port
// is released before it is returned, so another process could take it in
// between: fine on a test machine, not for production.
#ifndef MESHSEEK_COMMON_RPC_FREE_PORT_H_
#define MESHSEEK_COMMON_RPC_FREE_PORT_H_

#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

namespace meshseek::rpc {

inline int FreeLoopbackPort() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr);
  socklen_t len = sizeof addr;
  getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
  close(fd);
  return ntohs(addr.sin_port);
}

}  // namespace meshseek::rpc

#endif  // MESHSEEK_COMMON_RPC_FREE_PORT_H_
