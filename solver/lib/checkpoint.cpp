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
constexpr std::uint32_t kVersion = 8;  // 2: the header carries the build fingerprint; 3: State holds vHalf
                                       // and the reactions, frames the rod stress; 4: the loading clock and
                                       // the record's static elastic start; 5: history rows hold the kinetic
                                       // energy beyond the loading's motion; 6: ... and the inelastic zone's
                                       // reach, the record its edge warning; 7: the static start
                                       // records whether the model held a mechanism; 8: the record its
                                       // far-field rod break warning

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
  template <class T, class F>
  void items(const std::vector<T>& v, F each) {  // a count, then each item
    pod(static_cast<std::uint64_t>(v.size()));
    for (const T& x : v) each(x);
  }
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
  void vec(VecX& v) {  // the size the freshly built state has
    const Eigen::Index expected = v.size();
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
  template <class T, class F>
  void items(std::vector<T>& v, F each) {
    std::uint64_t n = 0;
    pod(n);
    if (n > (1ULL << 34)) throw CheckpointError("checkpoint '" + path + "' is corrupt (list of " + std::to_string(n) + ")");
    v.resize(n);
    for (T& x : v) each(x);
  }
};

// Every field a checkpoint holds, in file order: one list for writing (Io = Writer, const State and
// RunRecord) and reading (Io = Reader). The case and the header are written before it.
template <class Io, class S, class R>
void transferFields(Io& io, S& s, R& rec) {
  io.pod(s.step); io.pod(s.time); io.pod(s.appliedDisplacement);
  io.pod(s.loadingTime); io.pod(s.rateMultiplier); io.pod(s.rateMultiplierTarget); io.pod(s.rateRampSteps);
  io.vec(s.q); io.vec(s.v); io.vec(s.a); io.vec(s.vHalf); io.vec(s.reaction);
  io.vec(s.lambdaMax); io.vec(s.beamBroken); io.vec(s.deletionOrder);
  io.pod(s.externalWork); io.pod(s.dampingWork); io.pod(s.rodFractureEnergy); io.pod(s.lastExternalPower);
  io.pod(s.failedInterfaces); io.pod(s.crackAdvance);
  io.vec(rec.history);  // Measurement is plain data
  io.vec(rec.rcurveDa); io.vec(rec.rcurveJ);
  io.items(rec.frames, [&](auto& f) {
    io.pod(f.targetDa); io.pod(f.da); io.pod(f.step); io.pod(f.time); io.pod(f.appliedDisplacement);
    io.vec(f.nodeDisplacement); io.vec(f.ifaceDamage); io.vec(f.ifaceState); io.vec(f.beamBroken);
    io.vec(f.beamStress);
  });
  io.str(rec.status); io.str(rec.stopReason);
  io.pod(rec.wallSeconds); io.pod(rec.steps); io.pod(rec.maxKineticRatio);
  io.pod(rec.warnedBalance); io.pod(rec.warnedKinetic); io.pod(rec.warnedEdge); io.pod(rec.warnedFarFieldRod);
  io.items(rec.warnings, [&](auto& w) { io.str(w); });
  io.pod(rec.staticStart);
}

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
    transferFields(w, sim.state, rec);
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
  transferFields(r, s, rec);
  if (s.lambdaMax.size() != static_cast<std::size_t>(sim.model.numInterfaces()) ||
      s.beamBroken.size() != static_cast<std::size_t>(sim.model.numBeams()))
    throw CheckpointError("checkpoint '" + path + "' does not fit this model");
  char magic[8];
  r.in.read(magic, sizeof magic);
  if (!r.in || std::memcmp(magic, kMagic, sizeof magic) != 0)
    throw CheckpointError("checkpoint '" + path + "' is truncated");
  sim.replayDeletions();
}

}  // namespace enamel
