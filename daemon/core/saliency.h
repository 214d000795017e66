#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace everytouch::core {

// Histogram-based contrast saliency (Cheng et al., "Global contrast based salient region detection"; paper
// section VI.A.1, eq. 8-11): a pixel is as salient as its colour is far, in HSV, from the colours of all
// other pixels, weighted by how often they occur. Colours are quantised to levelsPerChannel^3 bins, the most
// frequent ones that cover `coverage` of the pixels are kept (at most maxColours; the paper keeps 85) and the
// rest join their nearest kept colour; each colour's saliency is then smoothed over its `smoothingFraction` *
// n nearest colours (eq. 10, m = n / 4).
struct SaliencyOptions {
    int levelsPerChannel = 12;        // quantisation of each of B, G, R
    double coverage = 0.95;           // fraction of pixels the kept colours must cover
    int maxColours = 85;              // at most this many colours are kept (the paper's 85)
    double smoothingFraction = 0.25;  // m = n / 4 nearest colours smooth each colour's saliency (eq. 10)
    int sampleStep =
        2;  // the histogram counts every sampleStep-th pixel in each direction: it is a frequency

    std::optional<std::string> validate() const;
};

// Buffers reused from frame to frame.
struct SaliencyScratch {
    std::vector<int> binCounts;
    std::vector<int> binToColour;
    std::vector<int> keptBins;
    std::vector<std::array<float, 3>> colourPoints;  // each kept colour in the HSV cone
    std::vector<float> frequency;
    std::vector<float> saliency;
    std::vector<float> smoothed;
    std::vector<std::pair<float, int>> neighbours;
    std::vector<float> binSaliency;
};

// texture: CV_8UC3 (BGR) or CV_8UC1. roi: the pixels to label (the histogram is taken over the whole image,
// since saliency is contrast against everything the camera sees). saliency: CV_32FC1, image size, in [0, 1]
// inside roi (the most salient colour 1, the least 0); left as it is outside roi.
void computeSaliency(const cv::Mat& texture, const cv::Rect& roi, const SaliencyOptions& options,
                     SaliencyScratch& scratch, cv::Mat& saliency);

}  // namespace everytouch::core
