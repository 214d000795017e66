#pragma once

#include <span>
#include <vector>

namespace everytouch::core {

// The linear assignment problem on a small rectangular cost matrix: pair rows with columns, each at most
// once, so that as many pairs as the smaller side allows are formed and their total cost is least. Solved
// exactly by shortest augmenting paths with dual potentials (Kuhn-Munkres in the O(n^2 m) form of Jonker and
// Volgenant), which for the ten or twenty rows of a frame's contacts costs microseconds.
//
// The solver keeps its buffers: after reserve() a problem of that size or smaller allocates nothing.
class LinearAssignment {
public:
    // Makes room for problems of up to rows x columns (either way round).
    void reserve(int rows, int columns);

    // `cost` holds rows x columns finite costs, row by row. On return rowToColumn[r] is the column paired
    // with row r, or -1 when rows > columns left it out. Returns the total cost of the pairs.
    double solve(int rows, int columns, std::span<const double> cost, std::vector<int>& rowToColumn);

private:
    // The algorithm proper, for rows <= columns; cost is read through `at`.
    template <typename Cost>
    void solveWide(int rows, int columns, Cost at, std::vector<int>& rowToColumn);

    std::vector<double> rowPotential_;
    std::vector<double> columnPotential_;
    std::vector<double> slack_;     // least reduced cost from the current tree to each column
    std::vector<int> columnOwner_;  // the row holding each column (1-based; 0: none); column 0 is the root
    std::vector<int> predecessor_;  // the column before each column on the augmenting path
    std::vector<char> visited_;     // columns in the current tree
    std::vector<int> transposed_;   // column -> row when the problem is solved transposed
};

}  // namespace everytouch::core
