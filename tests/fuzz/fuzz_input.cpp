#include "fuzz_input.h"

#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <system_error>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

namespace everytouch::fuzz {

namespace {

struct Scratch {
    std::filesystem::path path;
    Scratch() {
        std::string pattern = (std::filesystem::temp_directory_path() / "everytouch-fuzz-XXXXXX").string();
        if (!::mkdtemp(pattern.data()))
            throw std::system_error(errno, std::generic_category(), "mkdtemp " + pattern);
        path = pattern;
    }
    ~Scratch() {
        std::error_code ignored;
        std::filesystem::remove_all(path, ignored);
    }
};

}  // namespace

const std::filesystem::path& scratchDirectory() {
    static const Scratch scratch;
    return scratch.path;
}

const std::filesystem::path& recordingSkeleton() {
    static const std::filesystem::path directory = [] {
        const std::filesystem::path path = scratchDirectory() / "recording";
        std::filesystem::create_directories(path / "frames");
        std::filesystem::create_directories(path / "masks");
        cv::imwrite((path / "pattern.png").string(), cv::Mat(480, 640, CV_8UC1, cv::Scalar(255)));
        return path;
    }();
    return directory;
}

void writeFile(const std::filesystem::path& path, std::string_view bytes) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (!out)
        throw std::runtime_error("cannot write " + path.string());
}

std::vector<std::string_view> splitParts(const std::uint8_t* data, std::size_t size, std::size_t parts) {
    const std::string_view all(reinterpret_cast<const char*>(data), size);
    std::vector<std::string_view> pieces;
    std::size_t start = 0;
    while (pieces.size() + 1 < parts) {
        const std::size_t nul = all.find('\0', start);
        if (nul == std::string_view::npos)
            break;
        pieces.push_back(all.substr(start, nul - start));
        start = nul + 1;
    }
    pieces.push_back(all.substr(start));
    return pieces;
}

}  // namespace everytouch::fuzz
