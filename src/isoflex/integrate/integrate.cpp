// (room integrate: sources follow)
