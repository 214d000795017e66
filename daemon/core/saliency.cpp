#include "core/saliency.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace everytouch::core {

namespace {

// A colour as a point of the HSV cone, so that Euclidean distance respects the hue circle and shrinks hue
// differences where saturation or value is low: (s v cos h, s v sin h, v), each in [-1, 1].
std::array<float, 3> conePoint(float blue, float green, float red) {
    const float maximum = std::max({blue, green, red});
    const float minimum = std::min({blue, green, red});
    const float value = maximum / 255.0f;
    const float chroma = (maximum - minimum) / 255.0f;  // s * v
    float hue = 0.0f;                                   // radians
    if (chroma > 0.0f) {
        const float range = maximum - minimum;
        float sector;
        if (maximum == red)
            sector = std::fmod((green - blue) / range + 6.0f, 6.0f);
        else if (maximum == green)
            sector = (blue - red) / range + 2.0f;
        else
            sector = (red - green) / range + 4.0f;
        hue = sector * static_cast<float>(M_PI) / 3.0f;
    }
    return {chroma * std::cos(hue), chroma * std::sin(hue), value};
}

float distance(const std::array<float, 3>& a, const std::array<float, 3>& b) {
    const float dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
    return std::sqrt(dx * dx + dy * dy + dz * dz);
}

}  // namespace

std::optional<std::string> SaliencyOptions::validate() const {
    if (levelsPerChannel < 2 || levelsPerChannel > 64)
        return "levelsPerChannel: must be from 2 to 64";
    if (!(coverage > 0.0 && coverage <= 1.0))
        return "coverage: must be in (0, 1]";
    if (maxColours < 2)
        return "maxColours: must be at least 2";
    if (!(smoothingFraction > 0.0 && smoothingFraction <= 1.0))
        return "smoothingFraction: must be in (0, 1]";
    if (sampleStep < 1)
        return "sampleStep: must be at least 1";
    return std::nullopt;
}

void computeSaliency(const cv::Mat& texture, const cv::Rect& roi, const SaliencyOptions& options,
                     SaliencyScratch& scratch, cv::Mat& saliency) {
    CV_Assert(texture.type() == CV_8UC3 || texture.type() == CV_8UC1);
    saliency.create(texture.size(), CV_32FC1);
    const int levels = options.levelsPerChannel;
    const int bins = levels * levels * levels;
    const int channels = texture.channels();
    const auto binOf = [levels](const uchar* pixel, int channels) {
        if (channels == 1) {
            const int q = pixel[0] * levels >> 8;
            return (q * levels + q) * levels + q;
        }
        return ((pixel[2] * levels >> 8) * levels + (pixel[1] * levels >> 8)) * levels +
               (pixel[0] * levels >> 8);
    };

    std::vector<int>& counts = scratch.binCounts;
    counts.assign(bins, 0);
    int total = 0;
    for (int y = 0; y < texture.rows; y += options.sampleStep) {
        const uchar* row = texture.ptr<uchar>(y);
        for (int x = 0; x < texture.cols; x += options.sampleStep) {
            ++counts[binOf(row + x * channels, channels)];
            ++total;
        }
    }

    // The most frequent colours that cover the wanted share of the pixels.
    std::vector<int>& kept = scratch.keptBins;
    kept.clear();
    for (int bin = 0; bin < bins; ++bin)
        if (counts[bin] > 0)
            kept.push_back(bin);
    std::sort(kept.begin(), kept.end(), [&](int a, int b) { return counts[a] > counts[b]; });
    std::size_t keep = 0;
    for (int covered = 0; keep < kept.size(); ++keep) {
        if (keep >= static_cast<std::size_t>(options.maxColours) ||
            (keep >= 2 && covered >= options.coverage * total))
            break;
        covered += counts[kept[keep]];
    }

    const auto binPoint = [levels](int bin) {
        const float step = 256.0f / levels;
        const int r = bin / (levels * levels), g = bin / levels % levels, b = bin % levels;
        return conePoint((b + 0.5f) * step, (g + 0.5f) * step, (r + 0.5f) * step);
    };
    std::vector<std::array<float, 3>>& points = scratch.colourPoints;
    points.resize(keep);
    for (std::size_t i = 0; i < keep; ++i)
        points[i] = binPoint(kept[i]);

    // Every bin that occurs joins its nearest kept colour, and brings its count along.
    std::vector<int>& colourOf = scratch.binToColour;
    colourOf.assign(bins, -1);
    std::vector<float>& frequency = scratch.frequency;
    frequency.assign(keep, 0.0f);
    for (std::size_t i = 0; i < kept.size(); ++i) {
        const int bin = kept[i];
        int nearest = static_cast<int>(i);
        if (i >= keep) {
            const std::array<float, 3> point = binPoint(bin);
            float best = std::numeric_limits<float>::max();
            for (std::size_t j = 0; j < keep; ++j)
                if (const float d = distance(point, points[j]); d < best) {
                    best = d;
                    nearest = static_cast<int>(j);
                }
        }
        colourOf[bin] = nearest;
        frequency[nearest] += static_cast<float>(counts[bin]) / total;
    }

    // Eq. 9: contrast against all colours, weighted by their frequency.
    std::vector<float>& colourSaliency = scratch.saliency;
    colourSaliency.assign(keep, 0.0f);
    for (std::size_t i = 0; i < keep; ++i)
        for (std::size_t j = 0; j < keep; ++j)
            colourSaliency[i] += frequency[j] * distance(points[i], points[j]);

    // Eq. 10-11: each colour's saliency becomes the distance-weighted mean over its m nearest colours.
    const std::size_t m = std::clamp<std::size_t>(
        static_cast<std::size_t>(std::lround(options.smoothingFraction * keep)), 2, keep);
    std::vector<float>& smoothed = scratch.smoothed;
    smoothed.assign(keep, 0.0f);
    std::vector<std::pair<float, int>>& near = scratch.neighbours;
    for (std::size_t i = 0; i < keep; ++i) {
        near.clear();
        for (std::size_t j = 0; j < keep; ++j)
            near.emplace_back(distance(points[i], points[j]), static_cast<int>(j));
        std::partial_sort(near.begin(), near.begin() + static_cast<long>(m), near.end());
        float sumDistances = 0.0f;
        for (std::size_t k = 0; k < m; ++k)
            sumDistances += near[k].first;
        if (sumDistances <= 0.0f) {
            smoothed[i] = colourSaliency[i];
            continue;
        }
        float weighted = 0.0f;
        for (std::size_t k = 0; k < m; ++k)
            weighted += (sumDistances - near[k].first) * colourSaliency[near[k].second];
        smoothed[i] = weighted / ((static_cast<float>(m) - 1.0f) * sumDistances);
    }
    const auto [low, high] = std::minmax_element(smoothed.begin(), smoothed.end());
    const float lowest = *low, range = std::max(*high - *low, 1e-6f);

    // Per bin, so that labelling a pixel is one lookup; bins not seen in the histogram take their nearest
    // kept colour when they first occur in the region.
    std::vector<float>& binSaliency = scratch.binSaliency;
    binSaliency.assign(bins, -1.0f);
    for (int bin : kept)
        binSaliency[bin] = (smoothed[colourOf[bin]] - lowest) / range;
    for (int y = roi.y; y < roi.y + roi.height; ++y) {
        const uchar* row = texture.ptr<uchar>(y);
        float* out = saliency.ptr<float>(y);
        for (int x = roi.x; x < roi.x + roi.width; ++x) {
            const int bin = binOf(row + x * channels, channels);
            if (binSaliency[bin] < 0.0f) {
                const std::array<float, 3> point = binPoint(bin);
                float best = std::numeric_limits<float>::max();
                int nearest = 0;
                for (std::size_t j = 0; j < keep; ++j)
                    if (const float d = distance(point, points[j]); d < best) {
                        best = d;
                        nearest = static_cast<int>(j);
                    }
                binSaliency[bin] = (smoothed[nearest] - lowest) / range;
            }
            out[x] = binSaliency[bin];
        }
    }
}

}  // namespace everytouch::core
