// amsa_rng.h: numpy's random streams in C++, bit for bit, for the C++ sensor nodes.
//
// A sensor's noise in amsa-phys comes from numpy (amsa_phys/engine/rng.py):
// SeedSequence(entropy=seed, spawn_key=(crc32(path),)) -> PCG64 -> Generator, then
// standard_normal (a 256-level ziggurat) and random. A C++ node must draw the very same
// numbers or lockstep stops being byte-identical, so this header ports the three
// algorithms as numpy specifies them:
//  - SeedSequence (numpy/random/bit_generator.pyx): the entropy and the spawn key as 32-bit
//    words, mixed into a pool of 4 by the hashmix/mix functions; generate_state gives the
//    PCG64 seed; spawn(n) appends the child's index to the spawn key;
//  - PCG64 (numpy's pcg64.h, O'Neill's XSL-RR 128/64): a 128-bit LCG, seeded by
//    pcg_setseq_128_srandom_r from generate_state(4, uint64);
//  - random() = (next64 >> 11) * 2**-53; standard_normal() = numpy's ziggurat, with numpy's
//    own tables (amsa_ziggurat.h) and libm's exp and log1p, as numpy calls them.
// tests/unit/test_cpp_rng.py compares it with numpy over millions of draws.
#pragma once

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "amsa_ziggurat.h"

namespace amsa {

// A non-negative integer as numpy coerces it: 32-bit words, least significant first, [0] for 0.
inline std::vector<std::uint32_t> uint32_words(std::uint64_t n) {
  std::vector<std::uint32_t> out;
  if (n == 0) out.push_back(0);
  while (n > 0) {
    out.push_back(static_cast<std::uint32_t>(n & 0xFFFFFFFFu));
    n >>= 32;
  }
  return out;
}

// A decimal seed of any size (a scenario's ``seed``) as those words; throws if not digits.
inline std::vector<std::uint32_t> decimal_words(const std::string& text) {
  if (text.empty()) throw std::invalid_argument("an empty seed");
  std::vector<std::uint32_t> words(1, 0);
  for (char c : text) {
    if (c < '0' || c > '9') throw std::invalid_argument("seed " + text + " is not a non-negative integer");
    std::uint64_t carry = static_cast<std::uint64_t>(c - '0');
    for (std::uint32_t& w : words) {
      const std::uint64_t v = static_cast<std::uint64_t>(w) * 10u + carry;
      w = static_cast<std::uint32_t>(v & 0xFFFFFFFFu);
      carry = v >> 32;
    }
    if (carry) words.push_back(static_cast<std::uint32_t>(carry));
  }
  while (words.size() > 1 && words.back() == 0) words.pop_back();
  return words;
}

// numpy.random.SeedSequence with the default pool of 4 words.
class SeedSequence {
 public:
  SeedSequence(std::vector<std::uint32_t> entropy, std::vector<std::uint64_t> spawn_key)
      : entropy_(std::move(entropy)), spawn_key_(std::move(spawn_key)) {
    std::vector<std::uint32_t> words = entropy_;
    if (!spawn_key_.empty() && words.size() < kPool) words.resize(kPool, 0);
    for (std::uint64_t k : spawn_key_)
      for (std::uint32_t w : uint32_words(k)) words.push_back(w);
    std::uint32_t hc = kInitA;
    for (std::size_t i = 0; i < kPool; ++i) pool_[i] = hashmix(i < words.size() ? words[i] : 0, &hc);
    for (std::size_t s = 0; s < kPool; ++s)
      for (std::size_t d = 0; d < kPool; ++d)
        if (s != d) pool_[d] = mix(pool_[d], hashmix(pool_[s], &hc));
    for (std::size_t s = kPool; s < words.size(); ++s)
      for (std::size_t d = 0; d < kPool; ++d) pool_[d] = mix(pool_[d], hashmix(words[s], &hc));
  }

  // generate_state(n, np.uint64): 2n words, paired little-endian.
  std::vector<std::uint64_t> generate_state64(std::size_t n) const {
    std::uint32_t hc = kInitB;
    std::vector<std::uint32_t> w(2 * n);
    for (std::size_t i = 0; i < w.size(); ++i) {
      std::uint32_t v = pool_[i % kPool];
      v ^= hc;
      hc *= kMultB;
      v *= hc;
      v ^= v >> 16;
      w[i] = v;
    }
    std::vector<std::uint64_t> out(n);
    for (std::size_t i = 0; i < n; ++i)
      out[i] = static_cast<std::uint64_t>(w[2 * i]) | (static_cast<std::uint64_t>(w[2 * i + 1]) << 32);
    return out;
  }

  // spawn(n): children with this spawn key plus their index (counted across calls).
  std::vector<SeedSequence> spawn(std::size_t n) {
    std::vector<SeedSequence> out;
    for (std::size_t i = 0; i < n; ++i) {
      std::vector<std::uint64_t> key = spawn_key_;
      key.push_back(spawned_ + i);
      out.emplace_back(entropy_, key);
    }
    spawned_ += n;
    return out;
  }

 private:
  static constexpr std::size_t kPool = 4;
  static constexpr std::uint32_t kInitA = 0x43b0d7e5u, kMultA = 0x931e8875u;
  static constexpr std::uint32_t kInitB = 0x8b51f9ddu, kMultB = 0x58f38dedu;
  static constexpr std::uint32_t kMixL = 0xca01f9ddu, kMixR = 0x4973f715u;

  static std::uint32_t hashmix(std::uint32_t value, std::uint32_t* hc) {
    value ^= *hc;
    *hc *= kMultA;
    value *= *hc;
    value ^= value >> 16;
    return value;
  }
  static std::uint32_t mix(std::uint32_t x, std::uint32_t y) {
    std::uint32_t r = kMixL * x - kMixR * y;
    r ^= r >> 16;
    return r;
  }

  std::vector<std::uint32_t> entropy_;
  std::vector<std::uint64_t> spawn_key_;
  std::uint32_t pool_[kPool] = {0, 0, 0, 0};
  std::uint64_t spawned_ = 0;
};

// numpy.random.Generator(PCG64(seed_sequence)): the draws the sensors make.
class Generator {
 public:
  explicit Generator(SeedSequence seq) : seq_(std::move(seq)) {
    const std::vector<std::uint64_t> s = seq_.generate_state64(4);
    const u128 initstate = (static_cast<u128>(s[0]) << 64) | s[1];
    const u128 initseq = (static_cast<u128>(s[2]) << 64) | s[3];
    state_ = 0;
    inc_ = (initseq << 1) | 1u;
    step();
    state_ += initstate;
    step();
  }

  // Generator.spawn(n): generators on the children of this one's SeedSequence.
  std::vector<Generator> spawn(std::size_t n) {
    std::vector<Generator> out;
    for (SeedSequence& child : seq_.spawn(n)) out.emplace_back(child);
    return out;
  }

  std::uint64_t next64() {
    step();
    const std::uint64_t hi = static_cast<std::uint64_t>(state_ >> 64);
    const std::uint64_t lo = static_cast<std::uint64_t>(state_);
    const unsigned rot = static_cast<unsigned>(state_ >> 122);
    const std::uint64_t x = hi ^ lo;
    return (x >> rot) | (x << ((64u - rot) & 63u));
  }

  // Generator.random(): a double in [0, 1).
  double random() { return static_cast<double>(next64() >> 11) * (1.0 / 9007199254740992.0); }

  // Generator.standard_normal(): numpy's ziggurat, operation for operation.
  double standard_normal() {
    const double r_tail = 3.6541528853610087963519472518;
    const double inv_r = 0.27366123732975827203338247596;
    for (;;) {
      std::uint64_t r = next64();
      const int idx = static_cast<int>(r & 0xff);
      r >>= 8;
      const bool sign = r & 0x1;
      const std::uint64_t rabs = (r >> 1) & 0x000fffffffffffffULL;
      double x = static_cast<double>(rabs) * zig::wi_double[idx];
      if (sign) x = -x;
      if (rabs < zig::ki_double[idx]) return x;
      if (idx == 0) {
        for (;;) {
          const double xx = -inv_r * std::log1p(-random());
          const double yy = -std::log1p(-random());
          if (yy + yy > xx * xx) return ((rabs >> 8) & 0x1) ? -(r_tail + xx) : r_tail + xx;
        }
      }
      if ((zig::fi_double[idx - 1] - zig::fi_double[idx]) * random() + zig::fi_double[idx] <
          std::exp(-0.5 * x * x))
        return x;
    }
  }

 private:
  using u128 = unsigned __int128;
  void step() {
    const u128 mult = (static_cast<u128>(2549297995355413924ULL) << 64) | 4865540595714422341ULL;
    state_ = state_ * mult + inc_;
  }
  SeedSequence seq_;
  u128 state_ = 0, inc_ = 0;
};

// CPython's zlib.crc32 of a string (the key of a component's stream, engine/rng.py).
inline std::uint32_t crc32(const std::string& text) {
  std::uint32_t c = 0xFFFFFFFFu;
  for (unsigned char byte : text) {
    c ^= byte;
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
  }
  return c ^ 0xFFFFFFFFu;
}

// engine/rng.py component_rng(seed, path): the Generator of the component at ``path``.
inline Generator component_rng(const std::string& seed, const std::string& path) {
  return Generator(SeedSequence(decimal_words(seed), {crc32(path)}));
}

}  // namespace amsa
