#include "core/codeword_search.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/core.hpp>

namespace everytouch::core {

namespace {

// Chunks are grouped through a table with one entry per chunk value; this bounds its size (4 MB).
constexpr int kMaxChunkBits = 20;
// A random table lookup costs about this many codeword comparisons (a cache miss against a streamed
// popcount).
constexpr double kLookupCost = 8.0;

// Every mask of `bits` bits with at most `radius` ones, the empty mask first.
std::vector<std::uint64_t> masksWithinRadius(int bits, int radius) {
    std::vector<std::uint64_t> masks{0};
    std::size_t firstOfPreviousWeight = 0;
    for (int weight = 1; weight <= radius; ++weight) {
        const std::size_t end = masks.size();
        for (std::size_t i = firstOfPreviousWeight; i < end; ++i) {
            const std::uint64_t mask = masks[i];
            const int lowest = mask == 0 ? bits : std::countr_zero(mask);
            for (int bit = 0; bit < lowest; ++bit)
                masks.push_back(mask | (std::uint64_t{1} << bit));
        }
        firstOfPreviousWeight = end;
    }
    return masks;
}

double binomialSum(int n, int k) {
    double sum = 0;
    double term = 1;
    for (int i = 0; i <= k && i <= n; ++i) {
        sum += term;
        term = term * (n - i) / (i + 1);
    }
    return sum;
}

struct Chunk {
    int offset;
    int bits;
    std::uint64_t mask() const { return ((std::uint64_t{1} << bits) - 1) << offset; }
};

std::vector<Chunk> splitIntoChunks(int codeBits, int count) {
    std::vector<Chunk> chunks;
    int offset = 0;
    for (int c = 0; c < count; ++c) {
        const int bits = codeBits / count + (c < codeBits % count ? 1 : 0);
        chunks.push_back({offset, bits});
        offset += bits;
    }
    return chunks;
}

}  // namespace

EVERYTOUCH_HARDWARE_POPCOUNT void forEachPairWithin(
    const std::vector<std::uint64_t>& codes, int codeBits, int radius,
    const std::function<void(int a, int b, int distance)>& visit) {
    CV_Assert(codeBits >= 1 && codeBits <= 64 && radius >= 0 && radius <= kMaxCodewordSearchRadius);
    const double n = static_cast<double>(codes.size());
    int chunkCount = 0;
    double leastCost = std::numeric_limits<double>::infinity();
    const int fewestChunks = (codeBits + kMaxChunkBits - 1) / kMaxChunkBits;
    for (int m = fewestChunks; m <= std::max(fewestChunks, std::min(codeBits, radius + 1)); ++m) {
        double cost = 0;
        for (const Chunk& chunk : splitIntoChunks(codeBits, m)) {
            const double values = std::ldexp(1.0, chunk.bits);
            const double variants = binomialSum(chunk.bits, radius / m);
            cost += std::min(n, values) * variants * kLookupCost + n * n * variants / (2 * values);
        }
        if (cost < leastCost) {
            leastCost = cost;
            chunkCount = m;
        }
    }
    const std::vector<Chunk> chunks = splitIntoChunks(codeBits, chunkCount);
    const int chunkRadius = radius / chunkCount;

    std::vector<int> start;
    std::vector<int> order(codes.size());
    std::vector<std::uint64_t> grouped(codes.size());
    for (std::size_t c = 0; c < chunks.size(); ++c) {
        const Chunk& chunk = chunks[c];
        const std::size_t values = std::size_t{1} << chunk.bits;
        auto valueOf = [&](std::uint64_t code) { return (code >> chunk.offset) & (values - 1); };
        start.assign(values + 1, 0);
        for (std::uint64_t code : codes)
            ++start[valueOf(code) + 1];
        for (std::size_t v = 0; v < values; ++v)
            start[v + 1] += start[v];
        std::vector<int> fill(start.begin(), start.end() - 1);
        for (std::size_t i = 0; i < codes.size(); ++i) {
            const int at = fill[valueOf(codes[i])]++;
            order[at] = static_cast<int>(i);
            grouped[at] = codes[i];
        }

        // A pair belongs to the first chunk on which it agrees to within chunkRadius.
        auto reportedEarlier = [&](std::uint64_t difference) {
            for (std::size_t earlier = 0; earlier < c; ++earlier)
                if (std::popcount(difference & chunks[earlier].mask()) <= chunkRadius)
                    return true;
            return false;
        };
        const std::vector<std::uint64_t> variants = masksWithinRadius(chunk.bits, chunkRadius);
        for (std::size_t value = 0; value < values; ++value) {
            if (start[value] == start[value + 1])
                continue;
            for (std::uint64_t variant : variants) {
                const std::size_t partner = value ^ variant;
                if (partner < value)
                    continue;
                for (int i = start[value]; i < start[value + 1]; ++i) {
                    const int firstPartner = partner == value ? i + 1 : start[partner];
                    for (int j = firstPartner; j < start[partner + 1]; ++j) {
                        const std::uint64_t difference = grouped[i] ^ grouped[j];
                        const int distance = std::popcount(difference);
                        if (distance > radius || reportedEarlier(difference))
                            continue;
                        visit(std::min(order[i], order[j]), std::max(order[i], order[j]), distance);
                    }
                }
            }
        }
    }
}

NearCodewordTable::NearCodewordTable(int codeBits, int capacity, int radius)
    : lowBits_(codeBits / 2),
      lowMask_((std::uint64_t{1} << lowBits_) - 1),
      radius_(radius),
      halfRadius_(radius / 2),
      slotBits_(std::max(4, static_cast<int>(std::bit_width(2u * static_cast<unsigned>(capacity))))),
      slotMask_((std::size_t{1} << slotBits_) - 1),
      codes_(static_cast<std::size_t>(capacity), 0) {
    CV_Assert(codeBits >= 2 && codeBits <= 64 && capacity >= 0 && radius >= 0 &&
              radius <= kMaxCodewordSearchRadius);
    variants_[0] = masksWithinRadius(lowBits_, halfRadius_);
    variants_[1] = masksWithinRadius(codeBits - lowBits_, halfRadius_);
    for (std::vector<Slot>& slots : slots_)
        slots.assign(slotMask_ + 1, Slot{});
}

void NearCodewordTable::insert(int id, std::uint64_t code) {
    codes_[id] = code;
    for (int half = 0; half < 2; ++half) {
        std::vector<Slot>& slots = slots_[half];
        std::size_t at = home(half, halfOf(half, code));
        while (slots[at].id >= 0)
            at = (at + 1) & slotMask_;
        slots[at] = {code, id};
    }
}

void NearCodewordTable::remove(int id) {
    for (int half = 0; half < 2; ++half) {
        std::vector<Slot>& slots = slots_[half];
        std::size_t hole = home(half, halfOf(half, codes_[id]));
        while (slots[hole].id != id)
            hole = (hole + 1) & slotMask_;
        // Backward-shift deletion: pull later members of the run into the hole when their home slot allows,
        // so that every entry stays reachable from its home without tombstones.
        for (std::size_t next = (hole + 1) & slotMask_; slots[next].id >= 0; next = (next + 1) & slotMask_) {
            const std::size_t desired = home(half, halfOf(half, slots[next].code));
            if (((next - desired) & slotMask_) >= ((next - hole) & slotMask_)) {
                slots[hole] = slots[next];
                hole = next;
            }
        }
        slots[hole].id = -1;
    }
}

}  // namespace everytouch::core
