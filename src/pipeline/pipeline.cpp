#include "globemesh/pipeline.hpp"
