#include "core/fingertips.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Cholesky>

#include "core/geometry.h"

namespace everytouch::core {

namespace {

// A closed contour with arc lengths, addressed by unwrapped indices (any integer, taken modulo its size).
class Contour {
public:
    Contour(const cv::Point* points, int size, const std::vector<double>& arc, double length)
        : points_(points), size_(size), arc_(arc), length_(length) {}

    int size() const { return size_; }
    double length() const { return length_; }
    int wrap(int i) const {
        // Indices stay within a turn or two of the contour: a loop is cheaper than a division.
        while (i < 0)
            i += size_;
        while (i >= size_)
            i -= size_;
        return i;
    }
    Eigen::Vector2d at(int i) const {
        const cv::Point& p = points_[wrap(i)];
        return {p.x, p.y};
    }
    // Arc length of unwrapped index i, continuing past either end of the contour.
    double arc(int i) const {
        double turns = 0.0;
        for (; i < 0; i += size_)
            turns -= length_;
        for (; i >= size_; i -= size_)
            turns += length_;
        return arc_[i] + turns;
    }
    // The point at arc length `s` (unwrapped), interpolated between the contour points around it; `hint` is
    // an unwrapped index at or before it, advanced to the last point at or before `s`.
    Eigen::Vector2d pointAtArc(double s, int& hint) const {
        while (arc(hint + 1) <= s)
            ++hint;
        while (arc(hint) > s)
            --hint;
        const double span = arc(hint + 1) - arc(hint);
        const double f = span > 0.0 ? (s - arc(hint)) / span : 0.0;
        return at(hint) + f * (at(hint + 1) - at(hint));
    }

private:
    const cv::Point* points_;
    int size_;
    const std::vector<double>& arc_;
    double length_;
};

Eigen::Vector2d perpendicular(const Eigen::Vector2d& v) {
    return {-v.y(), v.x()};
}

// A finger's round end, in finger widths: the contour within kCapArc either way of its end holds it all (a
// half circle is 0.79 widths of contour on each side), and the part within kEndDepth of the end along the
// finger (the end's outer 120 degrees on a round tip) is fitted to find where it ends.
constexpr double kCapArc = 0.8;
constexpr double kEndDepth = 0.25;

// The contour point nearest to `point` within `halfSpan` of arc around `centre`.
int nearestPoint(const Contour& contour, int centre, double halfSpan, const Eigen::Vector2d& point) {
    int best = centre;
    const double s0 = contour.arc(centre);
    for (int i = centre - 1; s0 - contour.arc(i) <= halfSpan && i > centre - contour.size() / 2; --i)
        if ((contour.at(i) - point).squaredNorm() < (contour.at(best) - point).squaredNorm())
            best = i;
    for (int i = centre + 1; contour.arc(i) - s0 <= halfSpan && i < centre + contour.size() / 2; ++i)
        if ((contour.at(i) - point).squaredNorm() < (contour.at(best) - point).squaredNorm())
            best = i;
    return best;
}

// Where the silhouette ends along `direction` near contour point `centre`: a parabola across the finger
// fitted to the contour points within `depth` of the furthest one along `direction` (among those within
// `halfSpan` of arc around `centre`), and its vertex. The points are chosen by depth rather than by arc so
// that they lie symmetrically about the end whichever contour point is `centre`. Falls back to the
// furthest point when the points do not bend like a tip.
Eigen::Vector2d silhouetteEnd(const Contour& contour, int centre, double halfSpan, double depth,
                              const Eigen::Vector2d& direction) {
    const Eigen::Vector2d origin = contour.at(centre);
    const Eigen::Vector2d across = perpendicular(direction);
    const double s0 = contour.arc(centre);
    int first = centre, last = centre;
    while (s0 - contour.arc(first - 1) <= halfSpan && first > centre - contour.size() / 2)
        --first;
    while (contour.arc(last + 1) - s0 <= halfSpan && last < centre + contour.size() / 2)
        ++last;
    int furthest = centre;
    for (int i = first; i <= last; ++i)
        if ((contour.at(i) - origin).dot(direction) > (contour.at(furthest) - origin).dot(direction))
            furthest = i;
    const double uMin = (contour.at(furthest) - origin).dot(direction) - depth;
    Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
    Eigen::Vector3d right = Eigen::Vector3d::Zero();
    double acrossMin = 0.0, acrossMax = 0.0;
    for (int i = first; i <= last; ++i) {
        const Eigen::Vector2d q = contour.at(i) - origin;
        const double u = q.dot(direction), v = q.dot(across);
        if (u < uMin)
            continue;
        const Eigen::Vector3d basis(1.0, v, v * v);
        normal += basis * basis.transpose();
        right += basis * u;
        acrossMin = std::min(acrossMin, v), acrossMax = std::max(acrossMax, v);
    }
    const Eigen::Vector3d c = normal.ldlt().solve(right);
    if (c.allFinite() && c[2] < 0.0) {
        const double v = -c[1] / (2.0 * c[2]);
        if (v >= acrossMin && v <= acrossMax)
            return origin + (c[0] + c[1] * v + c[2] * v * v) * direction + v * across;
    }
    return contour.at(furthest);
}

// The finger around the candidate `median`: its axis runs from the middle of its sides, a step either way
// along the contour, to the tip, and the tip is where the silhouette ends along it. The median candidate
// need not sit at the end of a finger that is not symmetric about its axis, which tilts the axis; so the
// axis is taken again about the contour point at the end found. False when the shape is no finger.
bool refineTip(const Contour& contour, int median, const FingertipOptions& options, Fingertip& tip) {
    const double width = options.fingerWidthPx;
    const double step = options.stepWidths * width;
    int centre = median;
    for (int pass = 0; pass < 2; ++pass) {
        int hint = centre;
        const Eigen::Vector2d side1 = contour.pointAtArc(contour.arc(centre) - step, hint);
        const Eigen::Vector2d side2 = contour.pointAtArc(contour.arc(centre) + step, hint);
        const Eigen::Vector2d middle = 0.5 * (side1 + side2);
        const Eigen::Vector2d from = pass == 0 ? contour.at(centre) : tip.tip;
        Eigen::Vector2d direction = from - middle;
        const double length = direction.norm();
        if (length <= 0.0 || length < options.minLengthWidths * width)
            return false;
        direction /= length;
        const double across = std::abs((side2 - side1).dot(perpendicular(direction)));
        if (across < options.minWidthRatio * width || across > options.maxWidthRatio * width)
            return false;
        // The boundary pixels' centres lie inside the silhouette's edge by half a sampling step on average:
        // the edge is sampled along rows or columns, whichever it crosses more steeply, so the step along
        // its normal is 1 px for an edge along the grid and 0.71 px for a diagonal one.
        const double halfStep = 0.5 * std::max(std::abs(direction.x()), std::abs(direction.y()));
        tip.tip = silhouetteEnd(contour, centre, kCapArc * across, kEndDepth * across, direction) +
                  halfStep * direction;
        tip.direction = direction;
        tip.widthPx = across;
        centre = nearestPoint(contour, centre, kCapArc * across, tip.tip);
    }
    return true;
}

}  // namespace

std::optional<std::string> FingertipOptions::validate() const {
    if (!(fingerWidthPx >= 2.0))
        return "fingertips finger_width_px: must be at least 2 camera pixels";
    if (!(stepWidths > 0.8))
        return "fingertips step_widths: must exceed 0.8, the contour around half a rounded tip";
    if (!(maxAngleRad > 0.0 && maxAngleRad < M_PI))
        return "fingertips max_angle_rad: must lie between 0 and pi";
    if (!(minArmAngleRad >= 0.0 && minArmAngleRad <= M_PI))
        return "fingertips min_arm_angle_rad: must lie between 0 and pi";
    if (!(groupGapWidths > 0.0))
        return "fingertips group_gap_widths: must be positive";
    if (!(minLengthWidths >= 0.0))
        return "fingertips min_length_widths: must not be negative";
    if (!(minWidthRatio > 0.0 && maxWidthRatio > minWidthRatio))
        return "fingertips min_width_ratio, max_width_ratio: need 0 < min < max";
    if (!(minRegionWidths2 >= 0.0))
        return "fingertips min_region_widths2: must not be negative";
    if (!(minCutRegionWidths2 >= 0.0 && minCutRegionWidths2 <= minRegionWidths2))
        return "fingertips min_cut_region_widths2: must be in [0, min_region_widths2]";
    if (!(edgeMarginWidths >= 0.0 && edgeMarginWidths <= 2.0))
        return "fingertips edge_margin_widths: must be in [0, 2]";
    if (maxFingertips < 0)
        return "fingertips max_fingertips: must not be negative";
    if (!(padBackWidths >= 0.0))
        return "fingertips pad_back_widths: must not be negative";
    if (!padDrop.allFinite() || padDrop.determinant() == 0.0)
        return "fingertips pad_drop: must be a finite, invertible homography";
    return std::nullopt;
}

Eigen::Matrix3d padDropHomography(const Calibration& calibration, double heightMm) {
    return calibration.tableToCameraHomography(0.0) * calibration.tableToCameraHomography(heightMm).inverse();
}

FingertipOptions rigFingertipOptions(const Calibration& calibration, double fingerWidthMm,
                                     double endHeightMm) {
    // Millimetres per camera pixel at the image's centre: the square root of the area one pixel covers.
    const Eigen::Matrix3d cameraToTable = calibration.tableToCameraHomography(0.0).inverse();
    const Eigen::Vector2d centre(0.5 * (calibration.cameraSize.width - 1),
                                 0.5 * (calibration.cameraSize.height - 1));
    const Eigen::Vector2d origin = applyHomography(cameraToTable, centre);
    const Eigen::Vector2d alongX = applyHomography(cameraToTable, centre + Eigen::Vector2d::UnitX()) - origin;
    const Eigen::Vector2d alongY = applyHomography(cameraToTable, centre + Eigen::Vector2d::UnitY()) - origin;
    const double mmPerPixel = std::sqrt(std::abs(alongX.x() * alongY.y() - alongX.y() * alongY.x()));
    FingertipOptions options;
    options.fingerWidthPx = fingerWidthMm / mmPerPixel;
    options.padDrop = padDropHomography(calibration, endHeightMm);
    return options;
}

void findFingertips(const cv::Mat& handMask, const FingertipOptions& options, FingertipScratch& scratch,
                    Fingertips& fingertips, const cv::Mat& judged) {
    if (auto problem = options.validate())
        throw std::invalid_argument(*problem);
    if (!judged.empty() && (judged.type() != CV_8UC1 || judged.size() != handMask.size()))
        throw std::invalid_argument("findFingertips: the judged region must be CV_8UC1 of the mask's size");
    fingertips.clear();
    scratch.found.clear();
    const double width = options.fingerWidthPx;
    findOuterContours(handMask, options.minCutRegionWidths2 * width * width, scratch.contours);

    const double step = options.stepWidths * width;
    const double gap = options.groupGapWidths * width;
    const double cosLimit = std::cos(options.maxAngleRad);
    const double cosArmward = std::cos(options.minArmAngleRad);
    const int lastX = handMask.cols - 1, lastY = handMask.rows - 1;
    // Outside the image or outside what was judged, nothing is known: an edge there cuts an arm or a finger.
    const auto unknown = [&](int x, int y) {
        return x < 0 || y < 0 || x > lastX || y > lastY || (!judged.empty() && !judged.at<uchar>(y, x));
    };
    // The way out of what is known at a point, and whether it lies on that edge at all.
    const auto outward = [&](const cv::Point& q) {
        return cv::Point(unknown(q.x + 1, q.y) - unknown(q.x - 1, q.y),
                         unknown(q.x, q.y + 1) - unknown(q.x, q.y - 1));
    };
    const int margin = std::max(1, static_cast<int>(std::lround(options.edgeMarginWidths * width)));
    const auto nearEdge = [&](const cv::Point& q) {
        for (int dy = -margin; dy <= margin; ++dy)
            for (int dx = -margin; dx <= margin; ++dx)
                if (unknown(q.x + dx, q.y + dy))
                    return true;
        return false;
    };
    for (size_t region = 0; region < scratch.contours.contours.size(); ++region) {
        const ContourSpan& span = scratch.contours.contours[region];
        const cv::Point* points = scratch.contours.points.data() + span.begin;
        const int n = span.size;
        scratch.arc.resize(n);
        scratch.arc[0] = 0.0;
        for (int i = 1; i < n; ++i)
            scratch.arc[i] = scratch.arc[i - 1] + cv::norm(points[i] - points[i - 1]);
        const Contour contour(points, n, scratch.arc,
                              scratch.arc[n - 1] + cv::norm(points[0] - points[n - 1]));
        // Where the region leaves what is known: the outward normal of the edges it runs along, weighted by
        // how far. A hand reaches into the image from its forearm, so this is the way back to the wrist.
        int armwardX = 0, armwardY = 0;
        bool cut = false;
        for (int i = 0; i < n; ++i) {
            const cv::Point out = outward(points[i]);
            armwardX += out.x;
            armwardY += out.y;
            cut = cut || out != cv::Point(0, 0);
        }
        // A whole region needs the contour of a finger and some of its hand; a cut one only what the angle
        // test reaches from a tip, a step either way.
        if (cut ? contour.length() < 2.0 * step
                : contour.length() < 4.0 * step || span.area < options.minRegionWidths2 * width * width)
            continue;
        Eigen::Vector2d armward(armwardX, armwardY);
        if (armward.norm() > 0.0)
            armward.normalize();

        // Eq. 13-15 at every contour point; the peak/valley sign: the region lies on the right of the
        // contour's direction, so at a tip the contour turns right (a positive cross product in image
        // coordinates, y down).
        scratch.cosAngle.assign(n, 2.0);
        int before = 0, after = 0;
        for (int k = 0; k < n; ++k) {
            const double s = contour.arc(k);
            const Eigen::Vector2d p = contour.at(k);
            const Eigen::Vector2d v1 = p - contour.pointAtArc(s - step, before);
            const Eigen::Vector2d v2 = p - contour.pointAtArc(s + step, after);
            const double turn = v2.x() * v1.y() - v2.y() * v1.x();  // (T(k) - T(k-t)) x (T(k+t) - T(k))
            const double cosine = v1.dot(v2) / (v1.norm() * v2.norm());
            if (turn > 0.0 && cosine > cosLimit)
                scratch.cosAngle[k] = cosine;
        }

        // Groups of candidates, walked from a point that is none so that no group is split at the wrap.
        const auto firstNone = std::find(scratch.cosAngle.begin(), scratch.cosAngle.end(), 2.0);
        if (firstNone == scratch.cosAngle.end())
            continue;
        const int origin = static_cast<int>(firstNone - scratch.cosAngle.begin());
        for (int i = origin + 1; i < origin + n;) {
            if (scratch.cosAngle[contour.wrap(i)] > 1.0) {
                ++i;
                continue;
            }
            // One group: candidates no more than `gap` of contour apart, and whether it reaches the image's
            // edge, where the edge cuts an arm or a finger and makes a corner.
            const int first = i;
            int last = i, count = 0;
            for (int j = i; j < origin + n && contour.arc(j) - contour.arc(last) <= gap; ++j)
                if (scratch.cosAngle[contour.wrap(j)] <= 1.0)
                    last = j, ++count;
            i = last + 1;
            bool onEdge = false;
            for (int j = first; j <= last && !onEdge; ++j)
                onEdge = nearEdge(points[contour.wrap(j)]);
            if (onEdge)
                continue;
            int median = first;
            for (int seen = 0, j = first;; ++j)
                if (scratch.cosAngle[contour.wrap(j)] <= 1.0 && seen++ == count / 2) {
                    median = j;
                    break;
                }

            Fingertip tip;
            if (!refineTip(contour, median, options, tip) || tip.direction.dot(armward) > cosArmward)
                continue;
            tip.angleRad = std::acos(std::clamp(scratch.cosAngle[contour.wrap(median)], -1.0, 1.0));
            tip.hand = static_cast<int>(region);
            tip.pad = applyHomography(options.padDrop,
                                      tip.tip - options.padBackWidths * tip.widthPx * tip.direction);
            scratch.found.push_back(tip);
        }
    }
    // The sharpest tips when there are more than a frame can hold, in the order found.
    while (static_cast<int>(scratch.found.size()) > options.maxFingertips)
        scratch.found.erase(
            std::max_element(scratch.found.begin(), scratch.found.end(),
                             [](const Fingertip& a, const Fingertip& b) { return a.angleRad < b.angleRad; }));
    fingertips.insert(fingertips.end(), scratch.found.begin(), scratch.found.end());
}

}  // namespace everytouch::core
