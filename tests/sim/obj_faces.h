// A reference reader of an OBJ's own faces (fan-triangulated, no welding), independent of assimp and of the hull
// loader, so the loader's results can be checked against the raw file; and where the real hulls are.
#pragma once
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "sim/geometry/mesh.h"

namespace floesim::sim::testing {

inline TriMesh read_obj_faces(const std::filesystem::path& file) {
  TriMesh m;
  std::ifstream in(file);
  for (std::string line; std::getline(in, line);) {
    std::istringstream s(line);
    std::string tag;
    s >> tag;
    if (tag == "v") {
      double x, y, z;
      s >> x >> y >> z;
      m.vertices.emplace_back(x, y, z);
    } else if (tag == "f") {
      std::vector<int> f;
      for (std::string w; s >> w;) f.push_back(std::stoi(w) - 1);  // "i", "i/t" or "i/t/n": stoi stops at '/'
      for (size_t k = 1; k + 1 < f.size(); ++k) m.triangles.push_back({f[0], f[k], f[k + 1]});
    }
  }
  return m;
}

// A real hull of ../shared/data/hulls (read from there, never copied into the repository); a test failure if absent.
inline std::filesystem::path hull_file(const std::string& name) {
  const std::filesystem::path f = std::filesystem::path(FLOESIM_SHARED_DATA_DIR) / "hulls" / name;
  if (!std::filesystem::exists(f))
    ADD_FAILURE() << "test data missing: " << f << " (FLOESIM_SHARED_DATA_DIR must hold ../shared/data)";
  return f;
}

}  // namespace floesim::sim::testing
