#include "io/console_sink.h"

#include <cstdio>

#include "io/log.h"

namespace everytouch::io {

namespace {

std::string describe(const char* what, std::int64_t timestampUs, const core::Contact& contact) {
    char text[160];
    std::snprintf(text, sizeof text, "%9.3f s  contact %u %-6s at (%7.1f, %7.1f) px, height %5.1f mm",
                  static_cast<double>(timestampUs) * 1e-6, contact.id, what, contact.x, contact.y,
                  contact.heightMm);
    return text;
}

}  // namespace

void ConsoleSink::publish(std::uint64_t, std::int64_t timestampUs, const core::Contacts& contacts) {
    std::map<std::uint32_t, core::Contact> next;
    for (const core::Contact& contact : contacts) {
        next.emplace(contact.id, contact);
        const auto previous = current_.find(contact.id);
        const bool wasTouching = previous != current_.end() && previous->second.touching;
        if (contact.touching && !wasTouching)
            ET_LOG(Info) << describe("down", timestampUs, contact);
        else if (!contact.touching && wasTouching)
            ET_LOG(Info) << describe("up", timestampUs, contact);
        else
            ET_LOG(Debug) << describe(contact.touching ? "move" : "hover", timestampUs, contact);
    }
    for (const auto& [id, contact] : current_)
        if (contact.touching && !next.contains(id))
            ET_LOG(Info) << describe("up", timestampUs, contact);
    current_ = std::move(next);
}

}  // namespace everytouch::io
