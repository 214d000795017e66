// everytouch-sim-pictures: renders the pictures of docs/simulator.md into a directory: camera frames of
// several scenarios, surfaces and lights, the texture T and subtraction S of a frame pair, and its hand mask.
//   everytouch-sim-pictures DIR
// The first scenario at full size with its S, T and mask; the others at half size.
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "sim/sim_options.h"
#include "sim/simulator.h"

namespace {

using namespace everytouch;

struct Shot {
    std::string name;
    std::string scenario;
    double seconds;
    std::vector<std::pair<std::string, std::string>> options;
};

void save(const std::filesystem::path& path, const cv::Mat& image) {
    if (!cv::imwrite(path.string(), image))
        throw std::runtime_error("cannot write " + path.string());
    std::printf("%s\n", path.c_str());
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: everytouch-sim-pictures DIR\n");
        return 2;
    }
    const std::filesystem::path directory = argv[1];
    std::filesystem::create_directories(directory);
    const std::vector<Shot> shots{
        {"grid35-gray-normal", "grid35", 3.3, {}},
        {"multitouch-yellow-dark", "multitouch", 17.4, {{"surface", "yellow"}, {"light", "dark"}}},
        {"palm-artifacts-normal", "palm", 4.3, {{"surface", "artifacts"}, {"skin", "tan"}}},
        {"drag-gray-dark-ui", "drag", 6.0, {{"light", "dark"}, {"content", "ui"}, {"skin", "light"}}},
    };
    try {
        for (const Shot& shot : shots) {
            sim::SimParameters parameters;
            parameters.scenario = shot.scenario;
            for (const auto& [key, value] : shot.options)
                if (auto problem = sim::applyOption(parameters, key, value))
                    throw std::runtime_error(key + ": " + *problem);
            sim::Simulator simulator(parameters, sim::rigPattern(parameters));
            const auto index =
                static_cast<std::uint64_t>(shot.seconds * parameters.frameRate) & ~std::uint64_t{1};
            core::Frame positive, negative;
            sim::FrameTruth truth, unused;
            simulator.render(index, positive, truth);
            simulator.render(index + 1, negative, unused);
            if (&shot != &shots.front()) {
                cv::Mat small;  // the gallery at half size keeps the documentation light
                cv::resize(positive.image, small, {}, 0.5, 0.5, cv::INTER_AREA);
                save(directory / ("sim-" + shot.name + ".png"), small);
                continue;
            }
            save(directory / ("sim-" + shot.name + ".png"), positive.image);
            // Paper eq. 7 and the average of the pair: S = max_c (C - C'), shown x8; T = (C + C') / 2.
            cv::Mat difference, texture;
            cv::subtract(positive.image, negative.image, difference, cv::noArray(), CV_32F);
            std::vector<cv::Mat> channels;
            cv::split(difference, channels);
            cv::Mat s = cv::max(channels[0], cv::max(channels[1], channels[2]));
            s.convertTo(s, CV_8U, 8.0);
            cv::addWeighted(positive.image, 0.5, negative.image, 0.5, 0.0, texture);
            save(directory / ("sim-" + shot.name + "-S.png"), s);
            save(directory / ("sim-" + shot.name + "-T.png"), texture);
            save(directory / ("sim-" + shot.name + "-mask.png"), truth.handMask);
        }
    } catch (const std::exception& error) {
        std::fprintf(stderr, "everytouch-sim-pictures: %s\n", error.what());
        return 1;
    }
    return 0;
}
