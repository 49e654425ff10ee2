#include "codec/arithmetic_coder.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

namespace geomip::codec {
namespace {

struct Symbol {
  int bit;
  int context;  ///< −1: bypass
};

/// Random symbols over `num_contexts` contexts, context c emitting 1 with probability probs[c].
std::vector<Symbol> random_symbols(std::size_t n, const std::vector<double>& probs, double bypass_fraction,
                                   std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::uniform_int_distribution<int> pick(0, static_cast<int>(probs.size()) - 1);
  std::vector<Symbol> out(n);
  for (auto& s : out) {
    if (u(rng) < bypass_fraction) {
      s = {u(rng) < 0.5 ? 1 : 0, -1};
    } else {
      const int c = pick(rng);
      s = {u(rng) < probs[c] ? 1 : 0, c};
    }
  }
  return out;
}

std::vector<std::uint8_t> encode(const std::vector<Symbol>& symbols, int num_contexts) {
  ArithmeticEncoder enc;
  std::vector<Context> ctx(num_contexts);
  for (const auto& s : symbols) {
    if (s.context < 0) {
      enc.encode_bypass(s.bit);
    } else {
      enc.encode(s.bit, ctx[s.context]);
    }
  }
  return enc.finish();
}

/// Decodes symbols (their contexts known from `symbols`); returns how many decoded before exhaustion matched,
/// and checks every one of them.
std::size_t decode_prefix(std::span<const std::uint8_t> bytes, const std::vector<Symbol>& symbols,
                          int num_contexts, bool stop_at_exhaustion) {
  ArithmeticDecoder dec(bytes);
  std::vector<Context> ctx(num_contexts);
  std::size_t i = 0;
  for (; i < symbols.size(); ++i) {
    if (stop_at_exhaustion && dec.exhausted()) break;
    const auto& s = symbols[i];
    const int bit = s.context < 0 ? dec.decode_bypass() : dec.decode(ctx[s.context]);
    EXPECT_EQ(bit, s.bit) << "symbol " << i << " of " << symbols.size() << ", " << bytes.size() << " bytes";
    if (bit != s.bit) return i;
  }
  return i;
}

TEST(ArithmeticCoder, RoundTripsSkewedRandomBits) {
  for (std::uint32_t seed = 1; seed <= 20; ++seed) {
    const std::vector<double> probs = {0.01, 0.1, 0.3, 0.5, 0.8, 0.97, 0.999};
    const auto symbols = random_symbols(20000 + 997 * seed, probs, 0.1, seed);
    const auto bytes = encode(symbols, static_cast<int>(probs.size()));
    EXPECT_EQ(decode_prefix(bytes, symbols, static_cast<int>(probs.size()), false), symbols.size());
  }
}

TEST(ArithmeticCoder, ShortAndEmptyStreamsRoundTrip) {
  EXPECT_TRUE(encode({}, 1).empty());  // nothing coded: nothing written
  for (std::size_t n = 1; n < 64; ++n) {
    for (std::uint32_t seed = 0; seed < 20; ++seed) {
      const auto symbols = random_symbols(n, {0.2, 0.9}, 0.3, seed * 131 + static_cast<std::uint32_t>(n));
      const auto bytes = encode(symbols, 2);
      EXPECT_LE(bytes.size(), n / 8 + 5);
      EXPECT_EQ(decode_prefix(bytes, symbols, 2, false), n);
    }
  }
}

TEST(ArithmeticCoder, SizeIsNearTheEntropy) {
  // Stationary sources: the adaptive model should cost little more than the empirical entropy.
  for (double p : {0.02, 0.1, 0.25, 0.5}) {
    const std::size_t n = 200000;
    const auto symbols = random_symbols(n, {p}, 0.0, 7);
    std::size_t ones = 0;
    for (const auto& s : symbols) ones += s.bit;
    const double q = static_cast<double>(ones) / n;
    const double entropy_bits = n * -(q * std::log2(q) + (1 - q) * std::log2(1 - q));
    const auto bytes = encode(symbols, 1);
    const double bits = 8.0 * bytes.size();
    // Very skewed sources pay relatively more for the fast estimate's noise (2.9% at p = 0.02, measured).
    const double tolerance = p < 0.05 ? 1.04 : 1.02;
    EXPECT_LE(bits, entropy_bits * tolerance + 64) << "p = " << p;
    EXPECT_GE(bits, entropy_bits * 0.98 - 64) << "p = " << p;  // sanity: cannot beat the entropy by much
  }
}

TEST(ArithmeticCoder, LongRunsOfCertainSymbolsCarryCorrectly) {
  // Highly skewed symbols produce long 0xFF runs and carries.
  std::vector<Symbol> symbols;
  for (int r = 0; r < 50; ++r) {
    for (int i = 0; i < 5000; ++i) symbols.push_back({0, 0});
    symbols.push_back({1, 0});
    for (int i = 0; i < 3000; ++i) symbols.push_back({1, 1});
    symbols.push_back({0, 1});
  }
  const auto bytes = encode(symbols, 2);
  EXPECT_EQ(decode_prefix(bytes, symbols, 2, false), symbols.size());
}

TEST(ArithmeticCoder, EveryBytePrefixDecodesCorrectSymbolsUntilExhausted) {
  for (std::uint32_t seed = 1; seed <= 6; ++seed) {
    const auto symbols = random_symbols(6000, {0.05, 0.4, 0.7, 0.995}, 0.2, seed);
    const auto bytes = encode(symbols, 4);
    std::size_t previous = 0;
    for (std::size_t len = 0; len <= bytes.size(); ++len) {
      const std::span<const std::uint8_t> prefix(bytes.data(), len);
      const std::size_t decoded = decode_prefix(prefix, symbols, 4, true);
      EXPECT_GE(decoded, previous) << "longer prefix decoded fewer symbols";
      previous = decoded;
      if (len == bytes.size()) {
        EXPECT_GT(decoded, symbols.size() * 9 / 10);
      }
    }
  }
}

TEST(ArithmeticCoder, FlushIsShort) {
  // The flush costs at most a few bytes over the information content.
  for (std::uint32_t seed = 1; seed <= 50; ++seed) {
    const auto symbols = random_symbols(8 * 100, {0.5}, 1.0, seed);  // 800 bypass bits = 100 bytes
    const auto bytes = encode(symbols, 1);
    EXPECT_LE(bytes.size(), 102u);
  }
}

TEST(ArithmeticCoder, GarbageNeverReadsOutsideTheSpan) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 100; ++trial) {
    std::vector<std::uint8_t> garbage(rng() % 64);
    for (auto& b : garbage) b = static_cast<std::uint8_t>(rng());
    ArithmeticDecoder dec(garbage);
    Context c;
    for (int i = 0; i < 2000; ++i) (i % 3 == 0) ? dec.decode_bypass() : dec.decode(c);
    EXPECT_TRUE(dec.exhausted());
  }
}

}  // namespace
}  // namespace geomip::codec
