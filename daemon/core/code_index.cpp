#include "core/code_index.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include <opencv2/core.hpp>

#include "core/pattern.h"

namespace everytouch::core {

CodeIndex::CodeIndex(const cv::Mat& pattern, int window)
    : window_(window), chunkBits_((window * window + kChunks - 1) / kChunks) {
    CV_Assert(pattern.type() == CV_8UC1 && window >= 2 && window <= 8);
    codeMask_ = window * window == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << (window * window)) - 1;
    const std::vector<std::uint64_t> codes = windowCodes(pattern, window);
    const cv::Rect anchors = codedRegion(pattern.size(), window);
    entries_.reserve(codes.size());
    for (std::size_t i = 0; i < codes.size(); ++i) {
        const int column = static_cast<int>(i % static_cast<std::size_t>(anchors.width));
        const int row = static_cast<int>(i / static_cast<std::size_t>(anchors.width));
        entries_.push_back({codes[i], {anchors.x + column, anchors.y + row}});
    }
    std::sort(entries_.begin(), entries_.end(),
              [](const Entry& a, const Entry& b) { return a.code < b.code; });

    const std::size_t values = std::size_t{1} << chunkBits_;
    for (int chunk = 0; chunk < kChunks; ++chunk) {
        std::vector<int>& start = chunkStart_[chunk];
        start.assign(values + 1, 0);
        for (const Entry& entry : entries_)
            ++start[chunkOf(chunk, entry.code) + 1];
        for (std::size_t value = 0; value < values; ++value)
            start[value + 1] += start[value];
        std::vector<int> fill(start.begin(), start.end() - 1);
        std::vector<int>& grouped = chunkEntries_[chunk];
        grouped.resize(entries_.size());
        for (std::size_t i = 0; i < entries_.size(); ++i)
            grouped[fill[chunkOf(chunk, entries_[i].code)]++] = static_cast<int>(i);
    }
}

std::uint64_t CodeIndex::chunkOf(int chunk, std::uint64_t code) const {
    const int shift = chunk * chunkBits_;
    if (shift >= 64)
        return 0;
    return (code >> shift) & ((std::uint64_t{1} << chunkBits_) - 1);
}

double CodeIndex::chanceMatches(int knownBits, int mismatches) const {
    double sum = 0;
    double binomial = 1;  // C(knownBits, j)
    for (int j = 0; j <= mismatches && j <= knownBits; ++j) {
        sum += binomial;
        binomial = binomial * (knownBits - j) / (j + 1);
    }
    return static_cast<double>(entries_.size()) * std::ldexp(sum, -knownBits);
}

std::optional<cv::Point> CodeIndex::find(std::uint64_t code) const {
    const auto it =
        std::lower_bound(entries_.begin(), entries_.end(), code,
                         [](const Entry& entry, std::uint64_t value) { return entry.code < value; });
    if (it == entries_.end() || it->code != code)
        return std::nullopt;
    return it->position;
}

std::optional<CodeMatch> CodeIndex::match(const ObservedCode& observed, int maxMismatches) const {
    int best = -1;
    int bestMismatches = std::numeric_limits<int>::max();
    int runnerUp = std::numeric_limits<int>::max();
    // A window not yet examined disagrees with the observation on a known bit of every chunk searched so far.
    int searchedChunks = 0;
    for (int chunk = 0; chunk < kChunks && bestMismatches > searchedChunks; ++chunk) {
        const std::uint64_t unknown = chunkOf(chunk, ~observed.known & codeMask_);
        const int unknownCount = std::popcount(unknown);
        if (unknownCount > kMaxUnknownPerChunk)
            continue;
        ++searchedChunks;
        const std::uint64_t seen = chunkOf(chunk, observed.bits & observed.known);
        // Every assignment of the unknown bits: the submasks of `unknown`.
        std::uint64_t filling = 0;
        do {
            const std::uint64_t value = seen | filling;
            for (int k = chunkStart_[chunk][value]; k < chunkStart_[chunk][value + 1]; ++k) {
                const int i = chunkEntries_[chunk][k];
                if (i == best)
                    continue;
                const int mismatches = hammingDistance(entries_[i].code, observed);
                if (mismatches < bestMismatches) {
                    runnerUp = bestMismatches;
                    bestMismatches = mismatches;
                    best = i;
                } else if (mismatches < runnerUp) {
                    runnerUp = mismatches;
                }
            }
            filling = (filling - unknown) & unknown;
        } while (filling != 0);
    }
    if (best < 0 || bestMismatches > maxMismatches)
        return std::nullopt;
    return CodeMatch{entries_[best].position, bestMismatches, runnerUp};
}

}  // namespace everytouch::core
