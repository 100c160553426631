#include "sdf/grid.h"
