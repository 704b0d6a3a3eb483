// The one source of the object library stackbeam_test_pch (tests/CMakeLists.txt): it builds
// the precompiled header test_pch.hpp that every test program reuses.
