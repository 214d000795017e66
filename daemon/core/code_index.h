#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>

#include "core/observed_code.h"

namespace everytouch::core {

// The best window of the pattern for an observed code.
struct CodeMatch {
    cv::Point position;  // projector pixel: the bottom-right pixel (anchor) of the matching window
    int mismatches = 0;  // Hamming distance to the observation over its known bits
    // Smallest distance of any other window the search examined (those that agree with the observation on a
    // whole chunk, until no unexamined window can be closer than the best); a gap to `mismatches` says how
    // unambiguous the match is. INT_MAX when there was none.
    int runnerUpMismatches = std::numeric_limits<int>::max();
};

// From codeword to projector position: where on the panel a code seen by the camera was projected, found
// without knowing the homography of the surface it fell on.
class CodeIndex {
public:
    // pattern: CV_8UC1, 0/1 (core/pattern.h); window: its codeword window side.
    CodeIndex(const cv::Mat& pattern, int window);

    int window() const { return window_; }
    std::size_t size() const { return entries_.size(); }

    // The anchor of the window with exactly this codeword; one of them if the pattern repeats it.
    std::optional<cv::Point> find(std::uint64_t code) const;

    // The window closest to `observed` over its known bits, if within maxMismatches. Found for certain when
    // one of the codeword's four chunks (window*window/4 bits each) has no wrong bit and at most four unknown
    // bits, so any observation with at most three wrong bits and few unknown ones.
    std::optional<CodeMatch> match(const ObservedCode& observed, int maxMismatches) const;

    // Expected number of windows that agree with a random observation of `knownBits` bits in all but at most
    // `mismatches` of them: how likely a match that good is a coincidence. size() * sum_{j<=m} C(k, j) / 2^k.
    double chanceMatches(int knownBits, int mismatches) const;

private:
    static constexpr int kChunks = 4;
    // Unknown bits of a chunk are tried both ways, up to this many (16 variants); chunks with more are
    // skipped.
    static constexpr int kMaxUnknownPerChunk = 4;

    struct Entry {
        std::uint64_t code;
        cv::Point position;
    };

    std::uint64_t chunkOf(int chunk, std::uint64_t code) const;

    int window_;
    int chunkBits_;
    std::uint64_t codeMask_;      // the window*window bits a codeword has
    std::vector<Entry> entries_;  // sorted by code
    // Per chunk, entries_ indices grouped by the chunk's value: those with value v are
    // chunkEntries_[c][chunkStart_[c][v]] .. chunkEntries_[c][chunkStart_[c][v + 1] - 1].
    std::array<std::vector<int>, kChunks> chunkStart_;
    std::array<std::vector<int>, kChunks> chunkEntries_;
};

}  // namespace everytouch::core
