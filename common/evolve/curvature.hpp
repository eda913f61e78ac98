// Placeholder: curvature from a dense tile (issue 5), being written.
#pragma once
