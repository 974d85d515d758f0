#include "checkpoint.hpp"

#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <type_traits>

#include "version.hpp"

namespace enamel {

namespace {

constexpr char kMagic[8] = {'E', 'N', 'A', 'M', 'E', 'L', 'C', 'K'};
constexpr std::uint32_t kVersion = 2;  // 2: the header carries the build fingerprint

struct Writer {
  std::ofstream out;
  template <class T>
  void pod(const T& x) {
    static_assert(std::is_trivially_copyable_v<T>);
    out.write(reinterpret_cast<const char*>(&x), sizeof x);
  }
  template <class T>
  void vec(const std::vector<T>& v) {
    pod(static_cast<std::uint64_t>(v.size()));
    if (!v.empty()) out.write(reinterpret_cast<const char*>(v.data()), static_cast<std::streamsize>(v.size() * sizeof(T)));
  }
  void vec(const VecX& v) { vec(std::vector<double>(v.data(), v.data() + v.size())); }
  void str(const std::string& s) { vec(std::vector<char>(s.begin(), s.end())); }
};

struct Reader {
  std::ifstream in;
  std::string path;
  template <class T>
  void pod(T& x) {
    in.read(reinterpret_cast<char*>(&x), sizeof x);
    if (!in) throw CheckpointError("checkpoint '" + path + "' is truncated");
  }
  template <class T>
  void vec(std::vector<T>& v) {
    std::uint64_t n = 0;
    pod(n);
    if (n > (1ULL << 34)) throw CheckpointError("checkpoint '" + path + "' is corrupt (vector of " + std::to_string(n) + ")");
    v.resize(n);
    if (n) in.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(n * sizeof(T)));
    if (!in) throw CheckpointError("checkpoint '" + path + "' is truncated");
  }
  void vec(VecX& v, Eigen::Index expected) {
    std::vector<double> tmp;
    vec(tmp);
    if (static_cast<Eigen::Index>(tmp.size()) != expected)
      throw CheckpointError("checkpoint '" + path + "' does not fit this model (" + std::to_string(tmp.size()) +
                            " values for " + std::to_string(expected) + ")");
    v = Eigen::Map<VecX>(tmp.data(), expected);
  }
  void str(std::string& s) {
    std::vector<char> tmp;
    vec(tmp);
    s.assign(tmp.begin(), tmp.end());
  }
};

// The effective case without its comment lines (the source file as given, the preset, the --set options): the
// same case given by another path, or with a --set that repeats the value it has anyway, is the same case.
std::string effectiveKeys(const std::string& toml) {
  std::istringstream in(toml);
  std::string line, keys;
  while (std::getline(in, line))
    if (line.empty() || line[0] != '#') keys += line + "\n";
  return keys;
}

// The header: magic, format version, the build that wrote it, the effective case. Throws CheckpointError when
// the file is not a checkpoint of this format, this build and this case.
void readHeader(Reader& r, const std::string& caseToml) {
  const std::string& path = r.path;
  if (!r.in) throw CheckpointError("no checkpoint '" + path + "' to restart from");
  char magic[8];
  r.in.read(magic, sizeof magic);
  if (!r.in || std::memcmp(magic, kMagic, sizeof magic) != 0)
    throw CheckpointError("'" + path + "' is not an enamel-dem checkpoint");
  std::uint32_t version = 0;
  r.pod(version);
  if (version != kVersion)
    throw CheckpointError("checkpoint '" + path + "' has format version " + std::to_string(version) +
                          ", this build reads version " + std::to_string(kVersion));
  std::string build;
  r.str(build);
  if (build != buildFingerprint())
    throw CheckpointError("checkpoint '" + path + "' was written by another build of enamel-dem (" + build +
                          "; this is " + buildFingerprint() + "): its continuation would not be bit for bit");
  std::string toml;
  r.str(toml);
  if (effectiveKeys(toml) != effectiveKeys(caseToml))
    throw CheckpointError("checkpoint '" + path + "' was written for a different case (effective keys differ): "
                          "restart with the same case file, --preset and --set options");
}

}  // namespace

const std::string& buildFingerprint() {
  static const std::string fingerprint = [] {
    // FNV-1a over the executable's bytes: any rebuild that changes the machine code changes it.
    std::ifstream exe("/proc/self/exe", std::ios::binary);
    std::uint64_t h = 1469598103934665603ULL;
    char buf[1 << 16];
    while (exe.read(buf, sizeof buf) || exe.gcount() > 0) {
      for (std::streamsize i = 0; i < exe.gcount(); ++i) h = (h ^ static_cast<unsigned char>(buf[i])) * 1099511628211ULL;
      if (!exe) break;
    }
    char hex[17];
    std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
    return std::string(kGitHash) + " binary " + hex;
  }();
  return fingerprint;
}

void checkCheckpoint(const std::string& path, const CaseParams& params) {
  Reader r{std::ifstream(path, std::ios::binary), path};
  readHeader(r, params.tomlText);
}

void writeCheckpoint(const std::string& path, const Simulation& sim, const RunRecord& rec) {
  const std::string tmp = path + ".tmp";
  {
    Writer w{std::ofstream(tmp, std::ios::binary | std::ios::trunc)};
    if (!w.out) throw CheckpointError("cannot write checkpoint '" + tmp + "'");
    w.out.write(kMagic, sizeof kMagic);
    w.pod(kVersion);
    w.str(buildFingerprint());
    w.str(sim.params.tomlText);
    const State& s = sim.state;
    w.pod(s.step); w.pod(s.time); w.pod(s.appliedDisplacement);
    w.vec(s.q); w.vec(s.v); w.vec(s.a);
    w.vec(s.lambdaMax); w.vec(s.beamBroken); w.vec(s.deletionOrder);
    w.pod(s.externalWork); w.pod(s.dampingWork); w.pod(s.rodFractureEnergy); w.pod(s.lastExternalPower);
    w.pod(s.brokenBeams); w.pod(s.failedInterfaces); w.pod(s.crackAdvance);
    w.vec(sim.reaction);
    w.vec(rec.history);  // Measurement is plain data
    w.vec(rec.rcurveDa); w.vec(rec.rcurveJ);
    w.pod(static_cast<std::uint64_t>(rec.frames.size()));
    for (const Frame& f : rec.frames) {
      w.pod(f.targetDa); w.pod(f.da); w.pod(f.step); w.pod(f.time); w.pod(f.appliedDisplacement);
      w.vec(f.nodeDisplacement); w.vec(f.ifaceDamage); w.vec(f.ifaceState); w.vec(f.beamBroken);
    }
    w.str(rec.status); w.str(rec.stopReason);
    w.pod(rec.wallSeconds); w.pod(rec.steps); w.pod(rec.maxKineticRatio);
    w.pod(rec.warnedBalance); w.pod(rec.warnedKinetic);
    w.pod(static_cast<std::uint64_t>(rec.warnings.size()));
    for (const auto& s2 : rec.warnings) w.str(s2);
    w.out.write(kMagic, sizeof kMagic);  // trailer: a complete file ends with the magic again
    w.out.flush();
    if (!w.out) throw CheckpointError("cannot write checkpoint '" + tmp + "' (disk full?)");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0)
    throw CheckpointError("cannot rename '" + tmp + "' to '" + path + "'");
}

void readCheckpoint(const std::string& path, Simulation& sim, RunRecord& rec) {
  Reader r{std::ifstream(path, std::ios::binary), path};
  readHeader(r, sim.params.tomlText);
  State& s = sim.state;
  const Eigen::Index n = sim.model.numDofs();
  r.pod(s.step); r.pod(s.time); r.pod(s.appliedDisplacement);
  r.vec(s.q, n); r.vec(s.v, n); r.vec(s.a, n);
  r.vec(s.lambdaMax); r.vec(s.beamBroken); r.vec(s.deletionOrder);
  if (s.lambdaMax.size() != static_cast<std::size_t>(sim.model.numInterfaces()) ||
      s.beamBroken.size() != static_cast<std::size_t>(sim.model.numBeams()))
    throw CheckpointError("checkpoint '" + path + "' does not fit this model");
  r.pod(s.externalWork); r.pod(s.dampingWork); r.pod(s.rodFractureEnergy); r.pod(s.lastExternalPower);
  r.pod(s.brokenBeams); r.pod(s.failedInterfaces); r.pod(s.crackAdvance);
  r.vec(sim.reaction, static_cast<Eigen::Index>(sim.prescribedDofs.size()));
  r.vec(rec.history);
  r.vec(rec.rcurveDa); r.vec(rec.rcurveJ);
  std::uint64_t nf = 0;
  r.pod(nf);
  rec.frames.resize(nf);
  for (Frame& f : rec.frames) {
    r.pod(f.targetDa); r.pod(f.da); r.pod(f.step); r.pod(f.time); r.pod(f.appliedDisplacement);
    r.vec(f.nodeDisplacement); r.vec(f.ifaceDamage); r.vec(f.ifaceState); r.vec(f.beamBroken);
  }
  r.str(rec.status); r.str(rec.stopReason);
  r.pod(rec.wallSeconds); r.pod(rec.steps); r.pod(rec.maxKineticRatio);
  r.pod(rec.warnedBalance); r.pod(rec.warnedKinetic);
  std::uint64_t nw = 0;
  r.pod(nw);
  rec.warnings.resize(nw);
  for (auto& w : rec.warnings) r.str(w);
  char magic[8];
  r.in.read(magic, sizeof magic);
  if (!r.in || std::memcmp(magic, kMagic, sizeof magic) != 0)
    throw CheckpointError("checkpoint '" + path + "' is truncated");
  sim.replayDeletions();
}

}  // namespace enamel
