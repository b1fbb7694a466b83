function x = gpuArray(x)
% MATLAB's gpuArray for Octave (no GPU arrays): the array itself, on the CPU.
% ARCF's tracker_HOGCN.m calls gpuArray(zeros(...)) unconditionally in its ADMM h-step.
end
