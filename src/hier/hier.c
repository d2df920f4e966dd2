/* placeholder */
#include "core/core.h"
