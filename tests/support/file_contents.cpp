#include "support/file_contents.h"

#include <fstream>
#include <sstream>

namespace everytouch::test {

std::string fileContents(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

void writeText(const std::filesystem::path& path, const std::string& text) {
    std::ofstream(path) << text;
}

}  // namespace everytouch::test
