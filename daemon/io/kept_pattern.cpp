#include "io/kept_pattern.h"

#include <exception>
#include <string>

#include "core/pattern.h"
#include "io/log.h"
#include "io/recording.h"

namespace everytouch::io {

cv::Mat keptPattern(std::uint64_t seed, cv::Size size, const std::filesystem::path& directory) {
    const std::filesystem::path kept =
        directory.empty()
            ? std::filesystem::path()
            : directory / ("pattern-seed" + std::to_string(seed) + "-" + std::to_string(size.width) + "x" +
                           std::to_string(size.height) + ".png");
    if (!kept.empty() && std::filesystem::exists(kept)) {
        try {
            return readPatternImage(kept, size);
        } catch (const std::exception& error) {
            ET_LOG(Warning) << error.what() << "; the code pattern is generated again";
        }
    }
    core::PatternOptions options;
    options.size = size;
    options.seed = seed;
    cv::Mat pattern = core::generatePattern(options);
    if (!kept.empty()) {
        try {
            writePatternImage(kept, pattern);
        } catch (const std::exception& error) {
            ET_LOG(Warning) << "the code pattern is not kept for the next start: " << error.what();
        }
    }
    return pattern;
}

}  // namespace everytouch::io
