#include "sim/content.h"

#include <array>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "core/accuracy_grid.h"
#include "core/accuracy_targets.h"

namespace everytouch::sim {

namespace {

// Skin-coloured BGR values of several tones, as they appear in photographs.
const std::array<cv::Scalar, 4> kSkinColours{cv::Scalar(170, 190, 235), cv::Scalar(130, 160, 215),
                                             cv::Scalar(95, 125, 180), cv::Scalar(55, 75, 115)};

cv::Scalar randomColour(cv::RNG& rng, int low = 0, int high = 256) {
    return cv::Scalar(rng.uniform(low, high), rng.uniform(low, high), rng.uniform(low, high));
}

// Low-frequency random field in [0, 1]: white noise on a coarse grid, smoothly enlarged.
cv::Mat smoothNoise(cv::Size size, int cells, cv::RNG& rng) {
    cv::Mat coarse(std::max(2, size.height * cells / size.width), cells, CV_32F);
    rng.fill(coarse, cv::RNG::UNIFORM, 0.0, 1.0);
    cv::Mat field;
    cv::resize(coarse, field, size, 0, 0, cv::INTER_CUBIC);
    return field;
}

const char* randomWord(cv::RNG& rng) {
    static const std::array<const char*, 24> words{"table",   "touch",   "screen", "light", "code",  "finger",
                                                   "camera",  "project", "window", "open",  "file",  "edit",
                                                   "view",    "help",    "the",    "and",   "of",    "image",
                                                   "display", "pattern", "hand",   "press", "point", "draw"};
    return words[rng.uniform(0, static_cast<int>(words.size()))];
}

void drawTextLines(cv::Mat& image, cv::Rect area, double scale, const cv::Scalar& colour, cv::RNG& rng) {
    const int lineHeight = std::max(6, static_cast<int>(std::lround(22 * scale)));
    for (int y = area.y + lineHeight; y < area.y + area.height; y += lineHeight) {
        int x = area.x;
        const int end = area.x + area.width - static_cast<int>(rng.uniform(0, area.width / 3 + 1));
        while (true) {
            const char* word = randomWord(rng);
            int baseline = 0;
            const cv::Size extent = cv::getTextSize(word, cv::FONT_HERSHEY_SIMPLEX, scale, 1, &baseline);
            if (x + extent.width > end)
                break;
            cv::putText(image, word, {x, y}, cv::FONT_HERSHEY_SIMPLEX, scale, colour, 1, cv::LINE_AA);
            x += extent.width + static_cast<int>(8 * scale);
        }
    }
}

void drawFace(cv::Mat& image, cv::Point centre, int radius, const cv::Scalar& skin, cv::RNG& rng) {
    cv::ellipse(image, centre, {radius * 4 / 5, radius}, 0, 0, 360, skin, cv::FILLED, cv::LINE_AA);
    const cv::Scalar hair = randomColour(rng, 10, 90);
    cv::ellipse(image, centre - cv::Point(0, radius / 3), {radius * 5 / 6, radius * 3 / 4}, 0, 180, 360, hair,
                cv::FILLED, cv::LINE_AA);
    const cv::Scalar feature = skin * 0.55;
    cv::circle(image, centre + cv::Point(-radius / 3, 0), std::max(1, radius / 10), feature, cv::FILLED);
    cv::circle(image, centre + cv::Point(radius / 3, 0), std::max(1, radius / 10), feature, cv::FILLED);
    cv::ellipse(image, centre + cv::Point(0, radius / 2), {radius / 3, radius / 8}, 0, 0, 180, feature,
                std::max(1, radius / 15), cv::LINE_AA);
}

cv::Mat renderPhoto(cv::Size size, cv::RNG& rng) {
    cv::Mat image(size, CV_8UC3);
    // Sky: a vertical gradient with clouds.
    const cv::Mat clouds = smoothNoise(size, 12, rng);
    const cv::Vec3f skyTop(rng.uniform(150.f, 230.f), rng.uniform(90.f, 160.f), rng.uniform(40.f, 90.f));
    const cv::Vec3f skyLow(235, 215, 190);
    const int horizon = size.height * rng.uniform(40, 65) / 100;
    for (int y = 0; y < size.height; ++y)
        for (int x = 0; x < size.width; ++x) {
            const float s = std::min(1.0f, static_cast<float>(y) / horizon);
            const cv::Vec3f sky = skyTop * (1 - s) + skyLow * s;
            const float cloud = std::max(0.0f, clouds.at<float>(y, x) - 0.55f) * 2.0f;
            const cv::Vec3f value = sky * (1 - cloud) + cv::Vec3f(250, 250, 250) * cloud;
            image.at<cv::Vec3b>(y, x) =
                cv::Vec3b(cv::saturate_cast<uchar>(value[0]), cv::saturate_cast<uchar>(value[1]),
                          cv::saturate_cast<uchar>(value[2]));
        }
    // Hills with a textured meadow.
    const cv::Mat texture = smoothNoise(size, 60, rng);
    for (int hill = 0; hill < 3; ++hill) {
        const cv::Scalar green(rng.uniform(20, 80), rng.uniform(90, 170), rng.uniform(30, 110));
        std::vector<cv::Point> outline;
        const double phase = rng.uniform(0.0, 6.28), period = rng.uniform(0.6, 1.6);
        const int base = horizon + hill * size.height / 10;
        for (int x = 0; x <= size.width; x += 8)
            outline.emplace_back(x,
                                 base - static_cast<int>(size.height / 12 *
                                                         std::sin(phase + x * 6.28 / (period * size.width))));
        outline.emplace_back(size.width, size.height);
        outline.emplace_back(0, size.height);
        cv::fillPoly(image, std::vector<std::vector<cv::Point>>{outline}, green, cv::LINE_AA);
    }
    for (int y = horizon; y < size.height; ++y)
        for (int x = 0; x < size.width; ++x) {
            cv::Vec3b& pixel = image.at<cv::Vec3b>(y, x);
            const float shade = 0.8f + 0.4f * texture.at<float>(y, x);
            for (int c = 0; c < 3; ++c)
                pixel[c] = cv::saturate_cast<uchar>(pixel[c] * shade);
        }
    // Yellow flowers, a sun, and faces: skin-coloured and yellow objects, the paper's Fig. 13 hard cases.
    for (int i = 0; i < 25; ++i) {
        const cv::Point centre(rng.uniform(0, size.width), rng.uniform(horizon, size.height));
        const int radius = rng.uniform(3, 9) * size.width / 640 + 1;
        for (int petal = 0; petal < 6; ++petal) {
            const double angle = petal * M_PI / 3;
            cv::circle(image,
                       centre + cv::Point(static_cast<int>(radius * std::cos(angle)),
                                          static_cast<int>(radius * std::sin(angle))),
                       radius * 2 / 3 + 1, cv::Scalar(30, 210, 245), cv::FILLED, cv::LINE_AA);
        }
        cv::circle(image, centre, radius / 2 + 1, cv::Scalar(20, 110, 180), cv::FILLED, cv::LINE_AA);
    }
    cv::circle(image, {rng.uniform(size.width / 8, size.width * 7 / 8), horizon / 3}, size.width / 18,
               cv::Scalar(120, 230, 255), cv::FILLED, cv::LINE_AA);
    const int faces = rng.uniform(1, 4);
    for (int i = 0; i < faces; ++i) {
        const int radius = size.height * rng.uniform(10, 20) / 100;
        const cv::Point centre(size.width * (i + 1) / (faces + 1), size.height - radius * 3 / 2);
        const cv::Scalar shirt = randomColour(rng);
        cv::ellipse(image, centre + cv::Point(0, radius * 2), {radius * 3 / 2, radius * 6 / 5}, 0, 180, 360,
                    shirt, cv::FILLED, cv::LINE_AA);
        drawFace(image, centre, radius, kSkinColours[rng.uniform(0, 4)], rng);
    }
    cv::GaussianBlur(image, image, {0, 0}, 0.7);
    return image;
}

cv::Mat renderUi(cv::Size size, cv::RNG& rng) {
    cv::Mat image(size, CV_8UC3, randomColour(rng, 60, 200));
    const double scale = size.width / 640.0;
    // Desktop icons.
    for (int i = 0; i < 6; ++i) {
        const cv::Rect icon(static_cast<int>(12 * scale), static_cast<int>((12 + i * 60) * scale),
                            static_cast<int>(36 * scale), static_cast<int>(36 * scale));
        cv::rectangle(image, icon, randomColour(rng), cv::FILLED);
        cv::rectangle(image, icon, cv::Scalar(40, 40, 40), 1);
    }
    // Overlapping windows with title bars, buttons, text and an avatar.
    const int windows = rng.uniform(2, 5);
    for (int i = 0; i < windows; ++i) {
        const int w = size.width * rng.uniform(35, 70) / 100, h = size.height * rng.uniform(30, 60) / 100;
        const cv::Rect frame(rng.uniform(size.width / 10, size.width - w), rng.uniform(0, size.height - h), w,
                             h);
        cv::rectangle(image, frame, cv::Scalar(245, 245, 245), cv::FILLED);
        const int bar = static_cast<int>(24 * scale);
        const cv::Scalar accent = randomColour(rng, 40, 220);
        cv::rectangle(image, cv::Rect(frame.x, frame.y, frame.width, bar), accent, cv::FILLED);
        for (int b = 0; b < 3; ++b)
            cv::circle(image, {frame.x + frame.width - bar / 2 - b * bar, frame.y + bar / 2}, bar / 4,
                       cv::Scalar(60, 60, 220 - 60 * b), cv::FILLED, cv::LINE_AA);
        const cv::Rect body(frame.x + bar / 2, frame.y + bar * 3 / 2, frame.width - bar,
                            frame.height - bar * 3);
        if (rng.uniform(0, 2) == 0) {
            const int radius = std::min(body.width, body.height) / 5;
            drawFace(image, {body.x + radius + 4, body.y + radius + 4}, radius,
                     kSkinColours[rng.uniform(0, 4)], rng);
            drawTextLines(
                image, cv::Rect(body.x + radius * 2 + 12, body.y, body.width - radius * 2 - 12, body.height),
                0.45 * scale, cv::Scalar(30, 30, 30), rng);
        } else {
            drawTextLines(image, body, 0.45 * scale, cv::Scalar(30, 30, 30), rng);
        }
        for (int b = 0; b < 2; ++b) {
            const cv::Rect button(frame.x + frame.width - (b + 1) * static_cast<int>(80 * scale),
                                  frame.y + frame.height - bar * 5 / 4, static_cast<int>(70 * scale), bar);
            cv::rectangle(image, button, b == 0 ? accent : cv::Scalar(210, 210, 210), cv::FILLED);
        }
        cv::rectangle(image, frame, cv::Scalar(90, 90, 90), 1);
    }
    // Task bar.
    cv::rectangle(
        image,
        cv::Rect(0, size.height - static_cast<int>(28 * scale), size.width, static_cast<int>(28 * scale)),
        cv::Scalar(50, 45, 40), cv::FILLED);
    return image;
}

cv::Mat renderText(cv::Size size, cv::RNG& rng) {
    cv::Mat image(size, CV_8UC3, cv::Scalar(250, 250, 250));
    const double scale = size.width / 640.0;
    const int margin = static_cast<int>(40 * scale);
    cv::putText(image, "Touchscreen everywhere", {margin, margin + static_cast<int>(10 * scale)},
                cv::FONT_HERSHEY_DUPLEX, 0.9 * scale, cv::Scalar(20, 20, 20), 2, cv::LINE_AA);
    drawTextLines(image,
                  cv::Rect(margin, margin + static_cast<int>(25 * scale), size.width - 2 * margin,
                           size.height - 2 * margin - static_cast<int>(25 * scale)),
                  0.5 * scale, cv::Scalar(25, 25, 25), rng);
    return image;
}

}  // namespace

std::optional<ContentKind> contentKindFromName(std::string_view name) {
    for (ContentKind kind : {ContentKind::Grid35, ContentKind::Shapes, ContentKind::Photo, ContentKind::Ui,
                             ContentKind::Text, ContentKind::White, ContentKind::Gray})
        if (contentKindName(kind) == name)
            return kind;
    return std::nullopt;
}

std::string contentKindName(ContentKind kind) {
    switch (kind) {
        case ContentKind::Grid35:
            return "grid35";
        case ContentKind::Shapes:
            return "shapes";
        case ContentKind::Photo:
            return "photo";
        case ContentKind::Ui:
            return "ui";
        case ContentKind::Text:
            return "text";
        case ContentKind::White:
            return "white";
        case ContentKind::Gray:
            return "gray";
    }
    return {};
}

std::vector<cv::Point2d> grid35Centres(cv::Size size) {
    std::vector<cv::Point2d> centres;
    for (const core::DisplayPoint& centre : core::accuracyGridCentres(size.width, size.height))
        centres.emplace_back(centre.x, centre.y);
    return centres;
}

std::vector<std::vector<cv::Point2d>> dragShapes(cv::Size size) {
    const double w = size.width, h = size.height, side = std::min(w / 4.5, h / 2.2);
    const double top = (h - side) / 2;
    std::vector<std::vector<cv::Point2d>> shapes;
    const double squareLeft = w / 4 - side / 2;
    shapes.push_back({{squareLeft, top},
                      {squareLeft + side, top},
                      {squareLeft + side, top + side},
                      {squareLeft, top + side},
                      {squareLeft, top}});
    const double triangleLeft = w / 2 - side / 2;
    shapes.push_back({{triangleLeft, top},
                      {triangleLeft + side, top + side},
                      {triangleLeft, top + side},
                      {triangleLeft, top}});
    std::vector<cv::Point2d> circle;
    const cv::Point2d centre(w * 3 / 4, h / 2);
    for (int i = 0; i <= 72; ++i) {
        const double angle = -M_PI / 2 + i * 2 * M_PI / 72;
        circle.emplace_back(centre.x + side / 2 * std::cos(angle), centre.y + side / 2 * std::sin(angle));
    }
    shapes.push_back(circle);
    return shapes;
}

cv::Mat renderContent(ContentKind kind, cv::Size size, std::uint64_t seed, int variant) {
    cv::RNG rng(seed * 7919 + static_cast<std::uint64_t>(variant) * 104729 +
                static_cast<std::uint64_t>(kind));
    const double scale = size.width / 640.0;
    switch (kind) {
        case ContentKind::Grid35:
            return core::drawAccuracyTargets(size);
        case ContentKind::Shapes: {
            cv::Mat image(size, CV_8UC3, cv::Scalar(245, 245, 245));
            for (const auto& shape : dragShapes(size)) {
                std::vector<cv::Point> outline;
                for (const cv::Point2d& point : shape)
                    outline.emplace_back(static_cast<int>(std::lround(point.x)),
                                         static_cast<int>(std::lround(point.y)));
                cv::polylines(image, outline, false, cv::Scalar(120, 120, 120),
                              std::max(2, static_cast<int>(4 * scale)), cv::LINE_AA);
            }
            return image;
        }
        case ContentKind::Photo:
            return renderPhoto(size, rng);
        case ContentKind::Ui:
            return renderUi(size, rng);
        case ContentKind::Text:
            return renderText(size, rng);
        case ContentKind::White:
            return cv::Mat(size, CV_8UC3, cv::Scalar(255, 255, 255));
        case ContentKind::Gray:
            return cv::Mat(size, CV_8UC3, cv::Scalar(128, 128, 128));
    }
    return {};
}

}  // namespace everytouch::sim
