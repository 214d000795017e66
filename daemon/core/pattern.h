#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>

namespace everytouch::core {

// The binary code pattern of paper Section V.B. Every projector pixel p with a full window is labelled by the
// window x window block of pattern bits that has p as its bottom-right pixel (the window's "anchor"). Bit i
// of the codeword is the pattern bit at row i / window, column i % window of the block, counted from its
// top-left corner, so bit window*window - 1 is the anchor itself (paper eq. 16).
//
// The paper draws random patterns and keeps the best of 100 by mean distance, which guarantees nothing. Here
// a repair pass then flips single bits until every codeword is unique and windows that are not spatial
// neighbours differ in at least `minDistance` bits, so that that many bit errors are needed to mistake one
// place on the panel for another.
struct PatternOptions {
    cv::Size size{640, 480};  // projector panel, pixels
    int window = 6;           // codeword window side; window*window <= 64 bits
    std::uint64_t seed = 1;   // same seed, same pattern
    // Target of the repair pass: windows whose anchors are more than neighbourRadius apart differ in at least
    // this many bits. 0: no repair (the paper's plain random pattern, which repeats a codeword about every
    // other seed at 640x480); 1: every codeword unique. The pass raises the minimum one level at a time. With
    // 6x6 windows on 640x480, 4 takes about 10 000 trial flips (under a second); 5 is out of reach of
    // single-bit flips (each creates about 10 new near pairs): the pass spends its budget and leaves 4.
    int minDistance = 4;
    // Windows whose anchors are at most this many pixels apart (Chebyshev) may be closer than minDistance
    // (never identical): mistaking one for the other misplaces a code by that many projector pixels, which is
    // within what the camera-projector homography resolves anyway.
    int neighbourRadius = 1;
    // Upper bound on the bit flips the repair pass tries, per window of the pattern (0.1: 30 000 at 640x480,
    // three times what the default target needs). Bounds the generation time when minDistance is out of
    // reach; the pass stops as soon as the target holds.
    double repairTrialsPerWindow = 0.1;

    // The first problem found, naming the field; nothing when the options are usable.
    std::optional<std::string> validate() const;
};

// A pattern as described above: CV_8UC1 of options.size, values 0 and 1. Deterministic in the options.
// Throws std::invalid_argument when options.validate() fails.
cv::Mat generatePattern(const PatternOptions& options);

// Anchors (bottom-right pixels) that have a full window inside a pattern of this size.
cv::Rect codedRegion(cv::Size patternSize, int window);

// The codeword of the window anchored at `anchor`, which must lie in codedRegion(pattern.size(), window).
// pattern: CV_8UC1, values 0/1.
std::uint64_t codeAt(const cv::Mat& pattern, cv::Point anchor, int window);

// The codewords of every anchor in codedRegion, row by row.
std::vector<std::uint64_t> windowCodes(const cv::Mat& pattern, int window);

// How well a pattern separates its windows.
struct PatternAnalysis {
    std::size_t windowCount = 0;  // anchors with a full window
    // Windows whose codeword some other window also has.
    std::size_t repeatedWindows = 0;
    bool unique() const { return repeatedWindows == 0; }
    // Smallest Hamming distance between two windows whose anchors are more than neighbourRadius apart, or
    // between any two windows with the same codeword (then 0). Exact.
    int minDistance = 0;
    // Number of such pairs at distance d, for d = 0 .. closePairs.size() - 1. Exact.
    std::vector<std::size_t> closePairs;
    // Mean Hamming distance between two such windows, estimated from `samples` random pairs (about
    // window*window/2 for any pattern that looks random).
    double meanDistance = 0;
    // Mean over windows of the distance to the closest such window: what the paper reports as its mean
    // inter-codeword distance (4.524). Estimated from `samples` random windows, each against all windows.
    double meanNearestDistance = 0;
    int samples = 0;  // windows (pairs) behind the two estimated means
};

// Analyses a pattern (CV_8UC1, 0/1). samples: windows and pairs behind the estimated means; seed: which ones.
PatternAnalysis analyzePattern(const cv::Mat& pattern, int window, int neighbourRadius, int samples = 1000,
                               std::uint64_t seed = 1);

}  // namespace everytouch::core
