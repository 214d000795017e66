#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace everytouch::eval {

// The statistical skin-colour model (SCM) the paper compares with: the Gaussian mixtures of
//   M. J. Jones and J. M. Rehg, "Statistical Color Models with Application to Skin Detection",
//   International Journal of Computer Vision 46(1), 81-96, 2002 (also Compaq CRL technical report 98/11),
// 16 kernels with diagonal covariance for skin and 16 for non-skin in RGB, fitted there to about a billion
// labelled pixels of web images. Their published parameters are used as they are: nothing is trained on our
// recordings. A pixel is skin when P(rgb | skin) / P(rgb | non-skin) exceeds `likelihoodRatio`.
class SkinColourModel {
public:
    // 1: the maximum-likelihood decision, which assumes nothing about how much of an image is skin (a prior
    // would have to come from the scenes being scored).
    explicit SkinColourModel(double likelihoodRatio = 1.0);

    // texture: CV_8UC3 BGR. mask: receives CV_8UC1, 255 where the colour is skin.
    void segment(const cv::Mat& texture, cv::Mat& mask);

    // The two mixture densities at one colour (per DN^3).
    static double skinDensity(double r, double g, double b);
    static double nonSkinDensity(double r, double g, double b);

private:
    bool isSkin(std::uint32_t rgb);

    double likelihoodRatio_;
    // The decision for every 24-bit colour, evaluated when first seen: 0 unknown, 1 non-skin, 2 skin.
    std::vector<std::uint8_t> decisions_;
};

}  // namespace everytouch::eval
