#include "io/checkpoint.hpp"

#include <cstdio>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <type_traits>

#include "base/version.hpp"
#include "io/file_io.hpp"

namespace enamel {

namespace {

constexpr char kMagic[8] = {'E', 'N', 'A', 'M', 'E', 'L', 'C', 'K'};
// The format's version: a checkpoint of any other is refused (readHeader); raise it whenever what a checkpoint
// holds changes. This format holds, after the header (the build fingerprint and the effective case): State with
// vHalf, the reactions, the loading clock, the interface dissipation account (empty at beta = 1) and the margin
// rule's progress and forecast (State::lastProgress, lastForecast); the frames with the rod stress; history rows
// with the kinetic energy beyond the loading's motion and the inelastic zone's reach; the record with the static
// elastic start, whether the model held a mechanism, and the edge and far-field rod break warnings; then a
// CRC-32 of every byte before it (transferFields gives the order).
constexpr std::uint32_t kVersion = 11;
// The file: magic, version, build, case, fields (transferFields), CRC-32 of all that (4 bytes), magic.
constexpr std::size_t kTrailerBytes = sizeof(std::uint32_t) + sizeof kMagic;

std::string damaged(const std::string& path, const std::string& why) {
  return "checkpoint '" + path + "' is damaged (" + why + "): delete it to start the run from step 0";
}

struct Writer {
  std::string out;  // the whole file, written at once (writeFileAtomically)
  void bytes(const void* p, std::size_t n) { out.append(static_cast<const char*>(p), n); }
  template <class T>
  void pod(const T& x) {
    static_assert(std::is_trivially_copyable_v<T>);
    bytes(&x, sizeof x);
  }
  template <class T>
  void vec(const std::vector<T>& v) {
    pod(static_cast<std::uint64_t>(v.size()));
    if (!v.empty()) bytes(v.data(), v.size() * sizeof(T));
  }
  void vec(const VecX& v) { vec(std::vector<double>(v.data(), v.data() + v.size())); }
  void str(const std::string& s) { vec(std::vector<char>(s.begin(), s.end())); }
  template <class E>
  void named(const E& e) {  // a named enum (choices.hpp), by its name
    str(nameOf(e));
  }
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
    if (!in) throw CheckpointDamaged(damaged(path, "it ends inside a field"));
  }
  template <class T>
  void vec(std::vector<T>& v) {
    std::uint64_t n = 0;
    pod(n);
    if (n > (1ULL << 34)) throw CheckpointDamaged(damaged(path, "a vector of " + std::to_string(n)));
    v.resize(n);
    if (n) in.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(n * sizeof(T)));
    if (!in) throw CheckpointDamaged(damaged(path, "it ends inside a field"));
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
  template <class E>
  void named(E& e) {
    std::string name;
    str(name);
    const std::optional<E> value = enumFromName<E>(name);
    if (!value) throw CheckpointDamaged(damaged(path, "no such value '" + name + "'"));
    e = *value;
  }
  template <class T, class F>
  void items(std::vector<T>& v, F each) {
    std::uint64_t n = 0;
    pod(n);
    if (n > (1ULL << 34)) throw CheckpointDamaged(damaged(path, "a list of " + std::to_string(n)));
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
  io.named(rec.status); io.str(rec.stopReason);
  io.pod(rec.wallSeconds); io.pod(rec.steps); io.pod(rec.maxKineticRatio);
  io.pod(rec.warnedBalance); io.pod(rec.warnedKinetic); io.pod(rec.warnedEdge); io.pod(rec.warnedFarFieldRod);
  io.items(rec.warnings, [&](auto& w) { io.str(w); });
  io.pod(rec.staticStart);
  io.vec(s.lambdaMaxBooked); io.vec(s.ifaceDissipation);
  io.pod(s.lastProgress.loadingTime); io.vec(s.lastProgress.rods); io.vec(s.lastProgress.interfaces);
  io.pod(s.lastForecast.rowsToRodBreak); io.pod(s.lastForecast.rowsToInterfaceFailure);
  io.pod(s.lastForecast.rowsElapsed);
}

// The effective case's keys that can change a result, without its comment lines (the source file as given, the
// preset, the --set options): the same case given by another path, with a --set that repeats the value it has
// anyway, or with another value of a result-neutral key (case_params.hpp isResultNeutral: threads, checkpoint
// interval) is the same run. A key at its default counts as not given (case_params.hpp isDefaultKeyLine): the
// keys added since a checkpoint was written, at their defaults, leave its identity as it was.
std::string resultKeys(const std::string& toml) {
  std::istringstream in(toml);
  std::string line, keys;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (isResultNeutral(line.substr(0, line.find(" = "))) || isDefaultKeyLine(line)) continue;
    keys += line + "\n";
  }
  return keys;
}

// The stored checksum against the one of the bytes before it, read in pieces (a checkpoint may be larger than
// the memory a second copy would need). Throws CheckpointDamaged unless they match.
void verifyChecksum(std::ifstream& in, const std::string& path, std::uint64_t size) {
  const std::uint64_t body = size - kTrailerBytes;
  in.seekg(0);
  std::uint32_t crc = 0;
  std::vector<char> buf(1 << 20);
  for (std::uint64_t done = 0; done < body;) {
    const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(buf.size(), body - done));
    if (!in.read(buf.data(), static_cast<std::streamsize>(n))) throw CheckpointDamaged(damaged(path, "unreadable"));
    crc = crc32(buf.data(), n, crc);
    done += n;
  }
  std::uint32_t stored = 0;
  char magic[8];
  in.read(reinterpret_cast<char*>(&stored), sizeof stored);
  in.read(magic, sizeof magic);
  if (!in || std::memcmp(magic, kMagic, sizeof magic) != 0)
    throw CheckpointDamaged(damaged(path, "truncated or overwritten at its end"));
  if (stored != crc) {
    char why[96];
    std::snprintf(why, sizeof why, "checksum %08x, its bytes give %08x", stored, crc);
    throw CheckpointDamaged(damaged(path, why));
  }
  in.seekg(static_cast<std::streamoff>(sizeof kMagic + sizeof kVersion));
}

// The header: magic, format version, the build that wrote it, the effective case; the checksum over the whole
// file is checked before anything else is read from it. Throws CheckpointDamaged for a damaged file and
// CheckpointError when it is not a checkpoint of this format, this build and this case.
void readHeader(Reader& r, const std::string& caseToml) {
  const std::string& path = r.path;
  if (!r.in) throw CheckpointError("no checkpoint '" + path + "' to restart from");
  r.in.seekg(0, std::ios::end);
  const std::uint64_t size = static_cast<std::uint64_t>(r.in.tellg());
  r.in.seekg(0);
  char magic[8];
  r.in.read(magic, sizeof magic);
  if (!r.in || std::memcmp(magic, kMagic, sizeof magic) != 0)
    throw CheckpointDamaged(damaged(path, "it does not begin as an enamel-dem checkpoint"));
  std::uint32_t version = 0;
  r.pod(version);
  // A checkpoint of an earlier format carries no checksum: refused for its version (a damaged version field of
  // this format that happens to read as an earlier one is refused too, under that message).
  if (version == 0 || version > kVersion)
    throw CheckpointDamaged(damaged(path, "format version field " + std::to_string(version)));
  if (version != kVersion)
    throw CheckpointError("checkpoint '" + path + "' has format version " + std::to_string(version) +
                          ", this build reads version " + std::to_string(kVersion));
  if (size < sizeof kMagic + sizeof kVersion + kTrailerBytes)
    throw CheckpointDamaged(damaged(path, "truncated to " + std::to_string(size) + " bytes"));
  verifyChecksum(r.in, path, size);
  std::string build;
  r.str(build);
  if (build != buildFingerprint())
    throw CheckpointError("checkpoint '" + path + "' was written by another build of enamel-dem (" + build +
                          "; this is " + buildFingerprint() + "): its continuation would not be bit for bit");
  std::string toml;
  r.str(toml);
  if (resultKeys(toml) != resultKeys(caseToml))
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
  Writer w;
  w.bytes(kMagic, sizeof kMagic);
  w.pod(kVersion);
  w.str(buildFingerprint());
  w.str(sim.params.tomlText);
  transferFields(w, sim.state, rec);
  w.pod(crc32(w.out.data(), w.out.size()));  // trailer: the checksum of every byte before it, and the magic
  w.bytes(kMagic, sizeof kMagic);
  writeFileAtomically(path, w.out, "checkpoint");
}

void readCheckpoint(const std::string& path, Simulation& sim, RunRecord& rec) {
  Reader r{std::ifstream(path, std::ios::binary), path};
  readHeader(r, sim.params.tomlText);
  State& s = sim.state;
  transferFields(r, s, rec);
  if (s.lambdaMax.size() != static_cast<std::size_t>(sim.model.numInterfaces()) ||
      s.beamBroken.size() != static_cast<std::size_t>(sim.model.numBeams()) ||
      s.lambdaMaxBooked.size() != s.ifaceDissipation.size() ||
      (!s.lambdaMaxBooked.empty() && s.lambdaMaxBooked.size() != s.lambdaMax.size()))
    throw CheckpointError("checkpoint '" + path + "' does not fit this model");
  std::uint32_t crc = 0;
  r.pod(crc);  // checked by readHeader: what follows the fields is the trailer
  sim.replayDeletions();
}

}  // namespace enamel
