#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace everytouch::core {

// The paper's fusion of saliency and regions (section VI.A.3, eq. 12): a region k of the segmentation belongs
// to the hand when its confidence
//   C_F(k) = e^-(L-1) [alpha S(k) + beta S_N(k) + gamma A(k)]
// exceeds `threshold`, where S(k) is its mean saliency, S_N(k) the mean saliency of its neighbours, A(k) its
// area over the largest region's, and L the number of image sides it touches (a region on two or more sides
// is background; one side is where a hand enters, so the factor is 1 for L <= 1). With one neighbour
// (an isolated region) beta = 1/2 and alpha = gamma = 1/4; otherwise alpha = 1/2 and beta = gamma = 1/4.
struct ConfidenceOptions {
    double threshold = 0.5;  // C_F above this: hand. The terms lie in [0, 1] and their weights sum to 1.

    std::optional<std::string> validate() const;
};

struct ConfidenceScratch {
    std::vector<double> saliencySum;
    std::vector<int> area;
    std::vector<int> sides;
    std::vector<std::pair<int, int>> adjacency;
    std::vector<double> neighbourSaliency;
    std::vector<int> neighbourCount;
    std::vector<unsigned char> isHand;
};

// labels: CV_32SC1 over `roi` of an image of `imageSize` (segmentMeanShift's output), regions 0 .. count-1.
// saliency: CV_32FC1 of the same size as labels, in [0, 1]. mask: receives CV_8UC1 of labels' size, 255 on
// the regions judged hand.
void selectConfidentRegions(const cv::Mat& labels, int count, const cv::Mat& saliency, const cv::Rect& roi,
                            cv::Size imageSize, const ConfidenceOptions& options, ConfidenceScratch& scratch,
                            cv::Mat& mask);

}  // namespace everytouch::core
