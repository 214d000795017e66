// everytouch-pattern: generates the code pattern, reports how long that took and how well its windows are
// separated, and optionally saves it as a recording's pattern.png (255 where the bit is 1).
#include <chrono>
#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/pattern.h"

namespace {

void printAnalysis(const char* name, const everytouch::core::PatternAnalysis& analysis) {
    std::printf(
        "%s: %zu windows, %s (%zu repeated), minimum distance %d, mean distance %.3f, mean distance to "
        "the nearest window %.3f (means from %d samples); pairs at distance 0..%zu:",
        name, analysis.windowCount, analysis.unique() ? "unique" : "NOT unique", analysis.repeatedWindows,
        analysis.minDistance, analysis.meanDistance, analysis.meanNearestDistance, analysis.samples,
        analysis.closePairs.size() - 1);
    for (std::size_t pairs : analysis.closePairs)
        std::printf(" %zu", pairs);
    std::printf("\n");
}

}  // namespace

int main(int argc, char** argv) {
    using namespace everytouch;
    CLI::App app{"Generate the code pattern, time it and analyse its windows"};
    core::PatternOptions options;
    std::string output;
    int samples = 2000;
    bool compare = false;
    app.add_option("--width", options.size.width, "projector width, pixels");
    app.add_option("--height", options.size.height, "projector height, pixels");
    app.add_option("--window", options.window, "codeword window side");
    app.add_option("--seed", options.seed, "random seed");
    app.add_option("--min-distance", options.minDistance, "repair target (0: plain random)");
    app.add_option("--neighbour-radius", options.neighbourRadius, "windows this close may be closer");
    app.add_option("--samples", samples, "samples behind the estimated means")->check(CLI::PositiveNumber);
    app.add_flag("--compare", compare, "also analyse the plain random pattern of the same seed");
    app.add_option("--output", output, "write the pattern as an 8-bit PNG, 255 where the bit is 1");
    CLI11_PARSE(app, argc, argv);
    if (auto problem = options.validate()) {
        std::fprintf(stderr, "everytouch-pattern: %s\n", problem->c_str());
        return 2;
    }
    cv::setNumThreads(1);

    const auto start = std::chrono::steady_clock::now();
    const cv::Mat pattern = core::generatePattern(options);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("%dx%d, window %d, seed %llu, target minimum distance %d: generated in %.3f s\n",
                options.size.width, options.size.height, options.window,
                static_cast<unsigned long long>(options.seed), options.minDistance, seconds);
    printAnalysis("pattern", core::analyzePattern(pattern, options.window, options.neighbourRadius, samples));
    if (compare) {
        core::PatternOptions plain = options;
        plain.minDistance = 0;
        const cv::Mat random = core::generatePattern(plain);
        printAnalysis("plain random",
                      core::analyzePattern(random, options.window, options.neighbourRadius, samples));
        std::printf("bits flipped by the repair: %d\n", cv::countNonZero(random != pattern));
    }
    if (!output.empty() && !cv::imwrite(output, pattern * 255)) {
        std::fprintf(stderr, "everytouch-pattern: cannot write %s\n", output.c_str());
        return 1;
    }
    return 0;
}
