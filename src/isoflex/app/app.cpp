// (room app: sources follow)
