#include "core/codeword_search.h"

#include <algorithm>
#include <bit>
#include <random>
#include <set>
#include <tuple>

#include <gtest/gtest.h>

namespace everytouch::core {
namespace {

using Pair = std::tuple<int, int, int>;  // a < b, distance
using Neighbour = std::pair<int, int>;   // id, distance

// Random codewords, a quarter of them near copies of others (0..6 bits changed) so that close pairs exist at
// every width.
std::vector<std::uint64_t> codesWithNearCopies(int count, int bits, std::uint64_t seed) {
    std::mt19937_64 random(seed);
    const std::uint64_t mask = bits == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << bits) - 1;
    std::vector<std::uint64_t> codes;
    for (int i = 0; i < count; ++i) {
        if (i > 0 && i % 4 == 0) {
            std::uint64_t code = codes[random() % codes.size()];
            const int changes = static_cast<int>(random() % 7);
            for (int c = 0; c < changes; ++c)
                code ^= std::uint64_t{1} << (random() % bits);
            codes.push_back(code);
        } else {
            codes.push_back(random() & mask);
        }
    }
    return codes;
}

TEST(CodewordSearch, PairsWithinRadiusAreExactlyThoseOfAnExhaustiveSearch) {
    for (int bits : {16, 25, 36, 49, 64})
        for (int radius : {0, 1, 3, 5}) {
            const std::vector<std::uint64_t> codes = codesWithNearCopies(2000, bits, bits * 10 + radius);
            std::set<Pair> expected;
            for (int a = 0; a < static_cast<int>(codes.size()); ++a)
                for (int b = a + 1; b < static_cast<int>(codes.size()); ++b)
                    if (const int d = std::popcount(codes[a] ^ codes[b]); d <= radius)
                        expected.insert({a, b, d});
            std::vector<Pair> found;
            forEachPairWithin(codes, bits, radius, [&](int a, int b, int d) { found.push_back({a, b, d}); });
            const std::set<Pair> unique(found.begin(), found.end());
            EXPECT_EQ(unique.size(), found.size())
                << "a pair reported twice, " << bits << " bits, r " << radius;
            EXPECT_EQ(unique, expected) << bits << " bits, radius " << radius;
            EXPECT_FALSE(expected.empty()) << bits << " bits, radius " << radius;
        }
}

TEST(CodewordSearch, TableFindsExactlyTheStoredCodewordsWithinRadiusThroughInsertionsAndRemovals) {
    for (int bits : {20, 36, 64})
        for (int radius : {1, 3, 5}) {
            const int count = 3000;
            std::vector<std::uint64_t> codes = codesWithNearCopies(count, bits, bits + radius);
            NearCodewordTable table(bits, count, radius);
            std::vector<bool> stored(count, true);
            for (int id = 0; id < count; ++id)
                table.insert(id, codes[id]);
            // Remove a third, change some codewords and put a part back, so runs get holes and shifts.
            std::mt19937_64 random(7);
            for (int id = 0; id < count; id += 3) {
                table.remove(id);
                stored[id] = false;
                if (id % 2 == 0) {
                    codes[id] ^= std::uint64_t{1} << (random() % bits);
                    table.insert(id, codes[id]);
                    stored[id] = true;
                }
            }
            for (int query = 0; query < count; query += 7) {
                std::set<Neighbour> expected;
                for (int id = 0; id < count; ++id)
                    if (const int d = std::popcount(codes[id] ^ codes[query]); stored[id] && d <= radius)
                        expected.insert({id, d});
                std::vector<Neighbour> found;
                table.forEachWithin(codes[query], [&](int id, int d) { found.push_back({id, d}); });
                const std::set<Neighbour> unique(found.begin(), found.end());
                EXPECT_EQ(unique.size(), found.size());
                ASSERT_EQ(unique, expected) << bits << " bits, radius " << radius << ", query " << query;
            }
            for (int id = 0; id < count; ++id) {
                if (stored[id]) {
                    EXPECT_EQ(table.code(id), codes[id]);
                }
            }
        }
}

}  // namespace
}  // namespace everytouch::core
