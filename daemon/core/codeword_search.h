#pragma once

#include <bit>
#include <cstdint>
#include <functional>
#include <vector>

namespace everytouch::core {

// Searches among codewords for those within a few bits of each other, as pattern design needs them (Hamming
// space of up to 64 bits, hundreds of thousands of codewords, radius up to kMaxCodewordSearchRadius).
inline constexpr int kMaxCodewordSearchRadius = 5;

// Debian's amd64 baseline has no POPCNT instruction: std::popcount compiles to a library call there, which
// took 15 % of the default pattern's generation. The searches are compiled twice, the loader choosing the
// version with the instruction where the processor has it. On a function's definition only: a declaration
// would make every file that includes it resolve between clones it does not have.
// Not under the sanitizers: they instrument the loader's choice too, which runs before their runtime exists.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define EVERYTOUCH_HARDWARE_POPCOUNT
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define EVERYTOUCH_HARDWARE_POPCOUNT
#endif
#endif
#ifndef EVERYTOUCH_HARDWARE_POPCOUNT
#define EVERYTOUCH_HARDWARE_POPCOUNT __attribute__((target_clones("popcnt", "default")))
#endif

// Calls visit(a, b, distance) once for every pair a < b of `codes` (each codeBits long) at Hamming distance
// <= radius. Pigeonhole: split the codewords into m chunks; two codewords within `radius` agree to within
// radius / m bits on one chunk, so only codewords in nearby chunk groups are compared. m is chosen per call
// to minimise the work.
void forEachPairWithin(const std::vector<std::uint64_t>& codes, int codeBits, int radius,
                       const std::function<void(int a, int b, int distance)>& visit);

// Codewords by id (0 .. capacity-1), each id at most once, with insertion and removal, searchable for every
// stored codeword within `radius` of a query. Multi-index hashing: two codewords within radius r agree to
// within r/2 bits on one of their two halves; each half has an open-addressing table holding the codewords
// themselves, so a probe costs about one cache miss.
//
// The probes go unchecked by AddressSanitizer and ThreadSanitizer: every index is masked into its table, and
// each probe's shadow lookup is a cache miss of its own that the prefetch cannot hide, which made the
// default pattern's repair 30 times slower (28 s instead of 0.9 s) and a sanitized daemon slow to start.
#define EVERYTOUCH_UNCHECKED_PROBES __attribute__((no_sanitize("address", "thread")))

class NearCodewordTable {
public:
    NearCodewordTable(int codeBits, int capacity, int radius);

    EVERYTOUCH_UNCHECKED_PROBES void insert(int id, std::uint64_t code);
    EVERYTOUCH_UNCHECKED_PROBES void remove(int id);
    std::uint64_t code(int id) const { return codes_[id]; }

    // Calls visit(id, distance) once for every stored codeword within radius of `query`.
    template <typename Visit>
    EVERYTOUCH_UNCHECKED_PROBES EVERYTOUCH_HARDWARE_POPCOUNT void forEachWithin(std::uint64_t query,
                                                                                Visit&& visit) const {
        // The probes are independent cache misses: announce them all first so that they overlap.
        for (int half = 0; half < 2; ++half)
            for (std::uint64_t variant : variants_[half])
                __builtin_prefetch(&slots_[half][home(half, halfOf(half, query) ^ variant)]);
        for (int half = 0; half < 2; ++half) {
            const std::uint64_t key = halfOf(half, query);
            const std::vector<Slot>& slots = slots_[half];
            for (std::uint64_t variant : variants_[half]) {
                const std::uint64_t probe = key ^ variant;
                for (std::size_t at = home(half, probe); slots[at].id >= 0; at = (at + 1) & slotMask_) {
                    const std::uint64_t candidate = slots[at].code;
                    if (halfOf(half, candidate) != probe)
                        continue;
                    const int distance = std::popcount(candidate ^ query);
                    if (distance > radius_)
                        continue;
                    // Found through the first half already.
                    if (half == 1 && std::popcount(halfOf(0, candidate ^ query)) <= halfRadius_)
                        continue;
                    visit(slots[at].id, distance);
                }
            }
        }
    }

private:
    struct Slot {
        std::uint64_t code = 0;
        int id = -1;  // -1: empty
    };

    std::uint64_t halfOf(int half, std::uint64_t code) const {
        return half == 0 ? code & lowMask_ : code >> lowBits_;
    }
    std::size_t home(int half, std::uint64_t key) const {
        const std::uint64_t salt = half == 0 ? 0x9E3779B97F4A7C15ull : 0xC2B2AE3D27D4EB4Full;
        return static_cast<std::size_t>((key * salt) >> (64 - slotBits_));
    }

    int lowBits_;
    std::uint64_t lowMask_;
    int radius_;
    int halfRadius_;
    int slotBits_;
    std::size_t slotMask_;
    std::vector<std::uint64_t> codes_;
    std::vector<std::uint64_t> variants_[2];  // masks of a half with at most halfRadius_ bits set
    std::vector<Slot> slots_[2];
};

#undef EVERYTOUCH_UNCHECKED_PROBES

}  // namespace everytouch::core
