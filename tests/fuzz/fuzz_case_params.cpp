// libFuzzer target for the case parser (solver/lib/case/case_params.hpp): `make fuzz`.
//
// Input: the bytes are a case file (TOML text) for parseCase, with two kinds of directive lines
// taken out of the text first (so that they can carry any bytes) and blanked (line numbers stay):
//     #preset NAME       parse with that preset (ci | reduced | converged | paper; anything else: unknown preset)
//     #set key=value     one --set override, in order
// Without directive lines the whole input is the case file, with no preset and no --set.
//
// What counts as a finding (libFuzzer stops and writes the input to crash-*):
//   - a crash, a sanitizer report (ASan, UBSan), a leak, or a timeout / memory blow-up;
//   - any exception other than enamel::CaseError escaping parseCase (its documented error type);
//   - a CaseError whose exitCode is not one of the case-error codes, or whose message is empty;
//   - a broken round trip: case_params.hpp promises that parseCase(p.tomlText) gives the case back,
//     so the effective TOML must parse again, with no preset and no --set, to the same key lines.
#include "base/exit_codes.hpp"
#include "case/case_params.hpp"

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

namespace {

[[noreturn]] void fail(const char* what, const std::string& detail) {
    std::fprintf(stderr, "fuzz_case_params: %s\n%s\n", what, detail.c_str());
    std::abort();
}

bool startsWith(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

// The key lines of an effective case (tomlText without its '#' header and blank lines): what must
// survive a round trip. The header names the source, preset and --set, which legitimately differ.
std::string keyLines(const std::string& toml) {
    std::string out;
    std::size_t start = 0;
    while (start < toml.size()) {
        std::size_t end = toml.find('\n', start);
        if (end == std::string::npos) end = toml.size();
        const std::string line = toml.substr(start, end - start);
        if (!line.empty() && line[0] != '#') out += line + "\n";
        start = end + 1;
    }
    return out;
}

bool isCaseErrorCode(int code) {
    using namespace enamel::exit_code;
    return code == usage || code == malformed_toml || code == unknown_key || code == wrong_type ||
           code == out_of_range;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string input(reinterpret_cast<const char*>(data), size);

    // Split off the directive lines.
    std::string text, preset;
    std::vector<std::string> sets;
    std::size_t start = 0;
    while (start < input.size()) {
        std::size_t end = input.find('\n', start);
        const bool lastLine = end == std::string::npos;
        if (lastLine) end = input.size();
        const std::string line = input.substr(start, end - start);
        if (startsWith(line, "#set ")) sets.push_back(line.substr(5));
        else if (startsWith(line, "#preset ")) preset = line.substr(8);
        else text += line;
        if (!lastLine) text += '\n';
        start = end + 1;
    }

    enamel::CaseParams p;
    try {
        p = enamel::parseCase(text, "fuzz.toml", preset, sets);
    } catch (const enamel::CaseError& e) {
        if (!isCaseErrorCode(e.exitCode))
            fail("CaseError with an unexpected exit code", std::to_string(e.exitCode) + ": " + e.what());
        if (std::string(e.what()).empty()) fail("CaseError with an empty message", "");
        return 0;  // a bad case, rejected as documented
    } catch (const std::exception& e) {
        fail("an exception other than CaseError escaped parseCase", e.what());
    } catch (...) {
        fail("a non-std exception escaped parseCase", "");
    }

    // Accepted: the effective case must read back to itself.
    enamel::CaseParams q;
    try {
        q = enamel::parseCase(p.tomlText, "roundtrip.toml", "", {});
    } catch (const std::exception& e) {
        fail("the effective case (tomlText) of an accepted case does not parse again",
             std::string(e.what()) + "\n--- tomlText ---\n" + p.tomlText);
    }
    if (keyLines(q.tomlText) != keyLines(p.tomlText))
        fail("the effective case changes on a round trip",
             "--- first ---\n" + p.tomlText + "--- second ---\n" + q.tomlText);
    return 0;
}
