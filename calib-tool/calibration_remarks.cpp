#include "calibration_remarks.h"

#include <cctype>
#include <string_view>

namespace everytouch::calib {

std::vector<std::string> remarksOf(const std::string& message) {
    constexpr std::string_view kSeparator = "; ";
    std::vector<std::string> remarks;
    const std::size_t rms = message.find("RMS reprojection error");
    if (rms == std::string::npos)
        return remarks;
    std::size_t start = message.find(kSeparator, rms);
    while (start != std::string::npos) {
        start += kSeparator.size();
        const std::size_t end = message.find(kSeparator, start);
        std::string remark =
            message.substr(start, end == std::string::npos ? std::string::npos : end - start);
        if (!remark.empty()) {
            remark[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(remark[0])));
            remarks.push_back(std::move(remark));
        }
        start = end;
    }
    return remarks;
}

}  // namespace everytouch::calib
