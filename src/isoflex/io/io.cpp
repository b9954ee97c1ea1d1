// (room io: sources follow)
