// A recording directory (docs/file-formats.md) as everytouchd --rig replay and everytouch-eval open it:
// rig.yml, frames.csv and truth.csv are the input's first, second and third parts (cut at NUL bytes); the
// pattern and the frames the seeds name are written once, at the sizes the seeds give. Bad text may only give
// io::InputError; anything else is a finding.
#include <cstdint>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "fuzz_input.h"
#include "io/input_error.h"
#include "io/recording.h"

namespace {

const std::filesystem::path& recordingDirectory() {
    static const std::filesystem::path directory = [] {
        const std::filesystem::path& path = everytouch::fuzz::recordingSkeleton();
        const cv::Mat frame(488, 648, CV_8UC1, cv::Scalar(128));
        for (std::uint64_t index : {0, 1, 2, 3, 192, 193, 194, 195})
            cv::imwrite(everytouch::io::Recording::framePath(path, index).string(), frame);
        return path;
    }();
    return directory;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace everytouch;
    const std::filesystem::path& directory = recordingDirectory();
    const auto parts = fuzz::splitParts(data, size, 3);
    fuzz::writeFile(directory / "rig.yml", parts[0]);
    fuzz::writeFile(directory / "frames.csv", parts.size() > 1 ? parts[1] : std::string_view());
    if (parts.size() > 2)
        fuzz::writeFile(directory / "truth.csv", parts[2]);
    else
        std::filesystem::remove(directory / "truth.csv");
    try {
        const io::Recording recording = io::Recording::open(directory);
        if (!recording.frames().empty())
            (void)recording.loadFrame(0);
    } catch (const io::InputError&) {
    }
    return 0;
}
