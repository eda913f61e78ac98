#include <gtest/gtest.h>

#include "evolve/curvature.hpp"
