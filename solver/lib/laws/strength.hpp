// Rod-element strengths: one per rod element, normal distribution (mean, cv), seeded, negative
// draws redrawn (docs/model.md). Our own Box-Muller transform on std::mt19937_64, because
// std::normal_distribution differs between standard libraries and the seed must reproduce a run.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace enamel {

// Recorded in the output next to the seed.
constexpr const char* kStrengthGenerator = "mt19937_64 + Box-Muller, negative draws redrawn";

// n strengths s_i = mean (1 + cv z_i), z_i standard normal; draws with s_i <= 0 are redrawn.
// cv = 0 returns exactly `mean` for all n (no draws). The first m values do not depend on n.
// Throws std::invalid_argument unless mean > 0 is finite and 0 <= cv < 1 (cv in [0, 1), as the
// case key; cv near 1 would redraw ~16% of draws and skew the distribution).
std::vector<double> sampleRodStrengths(std::size_t n, double mean, double cv, std::uint64_t seed);

}  // namespace enamel
