#include "pipeline/provenance.h"

#include <openssl/evp.h>

#include <fstream>
#include <memory>

#include "pipeline/error.h"

#ifndef FLOESIM_VERSION
#define FLOESIM_VERSION "unknown"
#endif

namespace floesim {

const char* version() { return FLOESIM_VERSION; }

namespace {
std::string hex(const unsigned char* d, unsigned n) {
  static const char* k = "0123456789abcdef";
  std::string s;
  for (unsigned i = 0; i < n; ++i) {
    s += k[d[i] >> 4];
    s += k[d[i] & 15];
  }
  return s;
}

struct Sha256 {
  std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> ctx{EVP_MD_CTX_new(), &EVP_MD_CTX_free};
  Sha256() { EVP_DigestInit_ex(ctx.get(), EVP_sha256(), nullptr); }
  void update(const char* p, size_t n) { EVP_DigestUpdate(ctx.get(), p, n); }
  std::string final() {
    unsigned char d[EVP_MAX_MD_SIZE];
    unsigned n = 0;
    EVP_DigestFinal_ex(ctx.get(), d, &n);
    return hex(d, n);
  }
};
}  // namespace

std::string sha256_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Error(file.string() + ": cannot open to hash it");
  Sha256 h;
  std::vector<char> buf(1 << 16);
  while (in) {
    in.read(buf.data(), buf.size());
    h.update(buf.data(), static_cast<size_t>(in.gcount()));
  }
  return h.final();
}

std::string sha256_bytes(const std::string& bytes) {
  Sha256 h;
  h.update(bytes.data(), bytes.size());
  return h.final();
}

nlohmann::json make_provenance(const std::string& program, const std::vector<NamedInput>& inputs,
                               const nlohmann::json& resolved_config) {
  nlohmann::json p;
  p["program"] = program;
  p["version"] = version();
  nlohmann::json ins = nlohmann::json::array();
  for (auto& in : inputs)
    ins.push_back({{"role", in.role}, {"path", in.path.filename().string()}, {"sha256", sha256_file(in.path)}});
  p["inputs"] = ins;
  p["config"] = resolved_config;
  return p;
}

}  // namespace floesim
