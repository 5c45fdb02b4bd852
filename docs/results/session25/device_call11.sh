VOXBREAST_DEVICE=gpu timeout 200 bash scripts/gpu_run.sh run test_physics --gtest_filter="StepWorkGroup.*:StepList.*:UniformPath.*" 2>&1 | tail -32 | tee $OUT/gpu_tests_call11_h200.txt
