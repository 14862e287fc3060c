#pragma once
// Deterministic hashing for procedural content. Everything random in the
// virtual studio is a pure function of (seed, integer coordinates), so a
// render is identical whatever the thread count or the order of work.

#include <cmath>
#include <algorithm>
#include <cstdint>

namespace tega::synth {

inline uint64_t mix64(uint64_t x) {
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ull;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebull;
  x ^= x >> 31;
  return x;
}

inline uint64_t hash_combine(uint64_t seed, uint64_t value) {
  return mix64(seed ^ (value + 0x9e3779b97f4a7c15ull + (seed << 6) + (seed >> 2)));
}

template <class... Ints>
uint64_t hash_of(uint64_t seed, Ints... values) {
  uint64_t h = mix64(seed);
  ((h = hash_combine(h, static_cast<uint64_t>(static_cast<int64_t>(values)))), ...);
  return h;
}

// FNV-1a: a string's hash that is the same on every platform (std::hash is not).
inline uint64_t hash_string(const char* text) {
  uint64_t h = 0xcbf29ce484222325ull;
  for (; *text; ++text) h = (h ^ static_cast<unsigned char>(*text)) * 0x100000001b3ull;
  return h;
}

// Uniform in [0, 1).
inline double unit_from_hash(uint64_t h) { return static_cast<double>(h >> 11) * 0x1.0p-53; }

template <class... Ints>
double uniform(uint64_t seed, Ints... values) {
  return unit_from_hash(hash_of(seed, values...));
}

// Approximately standard normal (sum of four uniforms, rescaled): cheap and
// smooth enough for sensor noise.
template <class... Ints>
double gaussian(uint64_t seed, Ints... values) {
  const uint64_t h = hash_of(seed, values...);
  const double s = static_cast<double>(h & 0xffff) + static_cast<double>((h >> 16) & 0xffff) +
                   static_cast<double>((h >> 32) & 0xffff) + static_cast<double>(h >> 48);
  return (s / 65535.0 - 2.0) * std::sqrt(3.0);
}

// Smooth value noise in [0, 1] over the plane, one lattice cell per unit.
double value_noise(uint64_t seed, double x, double y);

inline double smoothstep(double edge0, double edge1, double x) {
  const double t = std::clamp((x - edge0) / (edge1 - edge0), 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

}  // namespace tega::synth
