#include <gtest/gtest.h>

#include "evolve/derivatives.hpp"
