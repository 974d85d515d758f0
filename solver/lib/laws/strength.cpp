// Rod-element strength sampling (see strength.hpp).
#include "laws/strength.hpp"

#include <cmath>
#include <random>
#include <stdexcept>

namespace enamel {

namespace {
// Uniform in [0, 1) from the top 53 bits of one mt19937_64 draw: u = (x >> 11) 2^-53.
double drawUniform(std::mt19937_64& rng) {
    return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}
}  // namespace

std::vector<double> sampleRodStrengths(std::size_t n, double mean, double cv, std::uint64_t seed) {
    if (!(std::isfinite(mean) && mean > 0)) throw std::invalid_argument("sampleRodStrengths: mean must be > 0 and finite");
    if (!(cv >= 0 && cv < 1)) throw std::invalid_argument("sampleRodStrengths: cv must be in [0, 1)");
    std::vector<double> strengths;
    strengths.reserve(n);
    if (cv == 0) {
        strengths.assign(n, mean);
        return strengths;
    }
    // Box-Muller: u1 in (0, 1], u2 in [0, 1),
    //   z0 = sqrt(-2 ln u1) cos(2 pi u2),  z1 = sqrt(-2 ln u1) sin(2 pi u2)   (independent N(0, 1)).
    // Both are used, in that order; s = mean (1 + cv z), kept only if s > 0.
    constexpr double kTwoPi = 6.283185307179586476925286766559;
    std::mt19937_64 rng(seed);
    while (strengths.size() < n) {
        const double u1 = 1.0 - drawUniform(rng);
        const double u2 = drawUniform(rng);
        const double r = std::sqrt(-2.0 * std::log(u1));
        for (double z : {r * std::cos(kTwoPi * u2), r * std::sin(kTwoPi * u2)}) {
            const double s = mean * (1.0 + cv * z);
            if (s > 0 && strengths.size() < n) strengths.push_back(s);
        }
    }
    return strengths;
}

}  // namespace enamel
