// Every artefact records how it was made: program, version, resolved configuration and input hashes.
// No timestamps or host names: the same inputs must give byte-identical artefacts.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace floesim {

const char* version();  // project version, e.g. "0.1.0"

std::string sha256_file(const std::filesystem::path& file);  // hex digest; Error if unreadable
std::string sha256_bytes(const std::string& bytes);

struct NamedInput {
  std::string role;  // "image", "floes", "hull", ...
  std::filesystem::path path;
};

nlohmann::json make_provenance(const std::string& program, const std::vector<NamedInput>& inputs,
                               const nlohmann::json& resolved_config);

}  // namespace floesim
