// Placeholder: upwind one-sided derivatives (issue 5), being written.
#pragma once
