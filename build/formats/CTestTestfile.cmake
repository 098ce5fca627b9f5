# CMake generated Testfile for 
# Source directory: /work/main/formats
# Build directory: /work/main/build/formats
# 
# This file includes the relevant testing commands required for 
# testing this directory and lists subdirectories to be tested as well.
