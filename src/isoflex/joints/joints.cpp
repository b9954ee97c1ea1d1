// (room joints: sources follow)
