// (room solve: sources follow)
