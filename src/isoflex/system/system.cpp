// (room system: sources follow)
