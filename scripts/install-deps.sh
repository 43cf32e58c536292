#!/usr/bin/env bash
# Installs exactly the Debian 12 packages meshseek needs to build, test and
# benchmark. Idempotent and quick when everything is already there; uses sudo
# when not run as root.
set -euo pipefail

# Packages that build the services and the CLI (the container image needs only
# these: install-deps.sh --build-only), then those of tests and benchmarks.
PACKAGES=(
  g++ cmake ninja-build pkg-config                   # toolchain
  libabsl-dev                                        # Status, flags, strings
  libopenmesh-dev                                    # mesh file readers
  libopencv-dev                                      # SIFT descriptor (features2d)
  libpng-dev                                         # PNG thumbnails and pictures (not OpenCV's imgcodecs: 65 ms a process start)
  libjpeg-dev                                        # JPEG pictures to query with (libjpeg-turbo)
  libflann-dev liblz4-dev                            # k-nearest-neighbour graph (RLD-SIFT)
  libgrpc++-dev protobuf-compiler-grpc libprotobuf-dev protobuf-compiler  # services
  libssl-dev                                         # OpenSSL, which gRPC's TLS uses: told not to tear down at exit
  libsqlite3-dev                                     # state of the stateful services
  zlib1g-dev                                         # CRC-32 of the coordinator's feature files
  prometheus-cpp-dev                                 # the services' Prometheus metrics (/metrics over HTTP)
  libcpp-httplib-dev                                 # the web gateway's HTTP server (meshseek web)
)
if [ "${1:-}" != "--build-only" ]; then
  PACKAGES+=(
    ccache python3                                   # faster rebuilds; python3 runs the reference evaluator
    python3-grpcio python3-protobuf                  # the Python client (python/) and its test
    chromium                                         # the web page's browser test (tests/web_browser_test.py)
    python3-websocket                                # ... drives headless Chromium over the DevTools protocol
    openssl                                          # tests/security_test makes a throwaway CA (deploy/make-certs.sh)
    libgtest-dev libgmock-dev libbenchmark-dev       # tests and benchmarks
    libfaiss-dev libopenblas-dev                     # HNSW candidates of the index (Faiss on OpenBLAS)
    clang llvm libclang-rt-14-dev                    # libFuzzer harnesses (tests/fuzz; the runtime and sanitizer headers are only recommended by clang), llvm-symbolizer
    libomp-14-dev                                    # ... OpenMP for clang, which Faiss needs to link
  )
fi

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
echo "install-deps: installing ${missing[*]}"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
