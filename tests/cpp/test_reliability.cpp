// Reliability without a mesh: the CRC-32 against its published check value, the file writer's failure path,
// the result-neutral keys, and the blow-up guard (runner.hpp blowUpCheck) on sound and blown-up history rows.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "case/case_params.hpp"
#include "io/file_io.hpp"
#include "run/runner.hpp"

using namespace enamel;

TEST(Crc32, PublishedCheckValue) {
  // CRC-32/ISO-HDLC (zlib, PNG): check value of "123456789" (the CRC catalogue's test string).
  EXPECT_EQ(crc32("123456789", 9), 0xCBF43926u);
  EXPECT_EQ(crc32("", 0), 0u);
  // continued in pieces, as checkpoint.cpp reads a large file
  EXPECT_EQ(crc32("6789", 4, crc32("12345", 5)), 0xCBF43926u);
  EXPECT_EQ(crc32("The quick brown fox jumps over the lazy dog", 43), 0x414FA339u);
}

TEST(FileIo, WriteIsAtomicAndAFailureSaysWhichFileAndHowMuch) {
  const auto dir = std::filesystem::temp_directory_path() / ("enamel-fileio-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "f.bin").string();
  writeFileAtomically(path, "first", "test file");
  writeFileAtomically(path, "second", "test file");
  std::ifstream in(path);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text, "second");
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
  try {
    writeFileAtomically((dir / "missing" / "f.bin").string(), std::string(1234, 'x'), "test file");
    FAIL() << "wrote into a missing directory";
  } catch (const WriteError& e) {
    EXPECT_FALSE(e.diskFull);
    EXPECT_NE(std::string(e.what()).find("cannot write test file '"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("(1234 bytes)"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

TEST(ResultNeutralKeys, AreCaseKeysAndOnlyThese) {
  int found = 0;
  for (const KeySpec& k : caseKeys()) found += isResultNeutral(k.name);
  EXPECT_EQ(found, static_cast<int>(std::size(kResultNeutralKeys)));
  EXPECT_TRUE(isResultNeutral("threads"));
  EXPECT_TRUE(isResultNeutral("checkpoint_interval_s"));
  for (const char* key : {"history_every", "zeta", "dt_factor", "theta_D", "seed", "max_steps"})
    EXPECT_FALSE(isResultNeutral(key)) << key;
}

namespace {

// A sound row: the energies balance to 1e-4 of the external work.
Measurement soundRow() {
  Measurement r;
  r.step = 1000;
  r.J = 2.0;
  r.external = 10.0;
  r.strainBeams = 4.0;
  r.strainInterfaces = 3.0;
  r.kinetic = 0.1;
  r.damping = 1.9;
  r.fracture = 0.999;
  return r;
}

GuardBounds bounds() { return guardBounds(/*Gamma=*/1.0, /*B=*/std::sqrt(3.0)); }

}  // namespace

TEST(Guard, SoundRowsPass) {
  EXPECT_EQ(blowUpCheck(soundRow(), 0.3, bounds()), "");
  Measurement atRest;  // the first row: nothing yet
  EXPECT_EQ(blowUpCheck(atRest, 0.0, bounds()), "");
  Measurement early = soundRow();  // little work yet, balanced to round-off: measured against the floor
  early.external = 1e-3, early.strainBeams = 1e-3, early.strainInterfaces = early.kinetic = early.damping = 0;
  early.fracture = 0, early.J = 1e-9;
  EXPECT_EQ(blowUpCheck(early, 0.0, bounds()), "");
}

TEST(Guard, EnergyBalanceIsCheckedWhateverTheSignOfTheWork) {
  // a damaged run as seen: external work -1e118 and energies of that size, "balance 0"
  Measurement r = soundRow();
  r.external = -1.4e118;
  r.kinetic = 6e117;
  r.strainBeams = 3e117;
  const std::string why = blowUpCheck(r, 0.0, bounds());
  EXPECT_NE(why.find("energy balance error"), std::string::npos) << why;
  Measurement small = soundRow();  // external work below the floor, energy from nowhere
  small.external = 0.0;
  small.kinetic = 1.0;
  EXPECT_NE(blowUpCheck(small, 0.0, bounds()).find("energy balance error"), std::string::npos);
  Measurement gained = soundRow();  // positive work, 40% more energy than was put in
  gained.kinetic += 4.0;
  EXPECT_NE(blowUpCheck(gained, 0.0, bounds()).find("energy balance error"), std::string::npos);
}

TEST(Guard, KineticOverStrainFailsAboveTenTimesTheLargestMeasured) {
  EXPECT_EQ(blowUpCheck(soundRow(), 0.322, bounds()), "");  // the largest ratio of a completed run measured
  EXPECT_EQ(blowUpCheck(soundRow(), 3.1, bounds()), "");
  EXPECT_NE(blowUpCheck(soundRow(), 3.3, bounds()), "");
  const std::string why = blowUpCheck(soundRow(), 60.0, bounds());  // the damaged run's ratio
  EXPECT_NE(why.find("kinetic / strain energy 60"), std::string::npos) << why;
}

TEST(Guard, NonFiniteJFailsARowNegativeJFailsAnRcurvePoint) {
  Measurement r = soundRow();
  r.J = -0.156;  // a history row's J may go negative in a sound run (rebound near the far edge)
  EXPECT_EQ(blowUpCheck(r, 0.0, bounds()), "");
  r.J = NAN;
  EXPECT_NE(blowUpCheck(r, 0.0, bounds()).find("non-finite state"), std::string::npos);
  Measurement k = soundRow();
  k.kinetic = INFINITY;
  EXPECT_NE(blowUpCheck(k, 0.0, bounds()).find("non-finite state"), std::string::npos);
  EXPECT_TRUE(resistanceIsPhysical(2.0, bounds()));
  EXPECT_TRUE(resistanceIsPhysical(-1e-12, bounds()));  // round-off
  EXPECT_FALSE(resistanceIsPhysical(-5.5e116, bounds()));  // the damaged run's R
  EXPECT_FALSE(resistanceIsPhysical(-1e-3, bounds()));
  EXPECT_FALSE(resistanceIsPhysical(NAN, bounds()));
  EXPECT_FALSE(resistanceIsPhysical(INFINITY, bounds()));
}
