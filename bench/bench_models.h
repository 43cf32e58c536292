// The meshes a per-model benchmark times: up to `max_models` files of `dir`
// (recursive, sorted by path), or, without a folder, one built-in
// icosphere of 20,480 triangles (a smoke run). A file that does not read
// ends the program with its error: a benchmark of fewer models than asked
// would mislead.
#ifndef MESHSEEK_BENCH_BENCH_MODELS_H_
#define MESHSEEK_BENCH_BENCH_MODELS_H_

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "common/geometry/icosphere.h"
#include "common/geometry/mesh_io.h"

namespace meshseek {

inline std::vector<TriangleMesh> LoadBenchModels(const std::string& dir, int max_models) {
  std::vector<TriangleMesh> out;
  if (dir.empty()) {
    out.push_back(Icosphere(5));
    return out;
  }
  std::vector<std::string> paths;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(dir)) {
    if (entry.is_regular_file() && MeshFormatFromPath(entry.path().string()).ok()) {
      paths.push_back(entry.path().string());
    }
  }
  std::sort(paths.begin(), paths.end());
  if (static_cast<int>(paths.size()) > max_models) paths.resize(max_models);
  for (const std::string& path : paths) {
    auto mesh = ReadMesh(path);
    if (!mesh.ok()) {
      std::cerr << mesh.status() << "\n";
      std::exit(1);
    }
    out.push_back(*std::move(mesh));
  }
  return out;
}

}  // namespace meshseek

#endif  // MESHSEEK_BENCH_BENCH_MODELS_H_
