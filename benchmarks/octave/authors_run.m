function authors_run(tracker_name, code_dir, frames_file, init_file, out_file)
% AUTHORS_RUN  One sequence through a runnable copy of the authors' tracker built by
% benchmarks/authors_octave.sh (GNU Octave).
%   tracker_name  'strcf' (their run_STRCF.m, hand-crafted), 'dr2track' (their run_DR2Track.m),
%                 'bacf' (ARCF's run_ARCF_H.m settings with BACF's: no aberrance term,
%                 learning rate 0.013, then their tracker_HOG.m), 'arcf' (ARCF-HC: their
%                 run_ARCF.m settings, then their tracker_HOGCN.m), 'autotrack' (their
%                 run_AutoTrack.m, which calls AutoTrack_optimized.m), 'eco_hc' (ECO's
%                 runfiles/testing_ECO_HC.m settings, then its tracker.m) or 'csrdcf' (CSR-DCF's
%                 create_csr_tracker.m / track_csr_tracker.m, read_default_csr_parameters.m)
%   code_dir      the built copy
%   frames_file   one image path per line, in frame order
%   init_file     the first frame's box, 1-based x,y,w,h
%   out_file      receives the boxes, 1-based x,y,w,h, one '%.4f' line per frame
% Prints the fps the authors' code measures itself.
  frames = strtrim(strsplit(strtrim(fileread(frames_file)), "\n"));
  init = dlmread(init_file);
  seq = struct();
  seq.name = 'seq';
  seq.video_path = fileparts(frames{1});
  seq.s_frames = frames(:);
  seq.init_rect = init(1, 1:4);
  seq.st_frame = 1; seq.en_frame = numel(frames); seq.len = numel(frames);
  seq.startFrame = 1; seq.endFrame = numel(frames);  % the ARCF code's names
  old = pwd; cd(code_dir);  % both resolve their folders and lookup tables from here
  switch lower(tracker_name)
    case 'strcf'
      setup_paths();  % theirs
      % Their run file's own settings, with its last line (the tracker call) made here
      % instead, after switching the figure window off (no display under batch Octave).
      body = regexprep(fileread('run_STRCF.m'), '^\s*function[^\n]*\n', '', 'once');
      call = 'results\s*=\s*tracker\(params\);';
      if numel(regexp(body, call)) ~= 1, error('authors_run: unexpected run_STRCF.m'); end
      eval(regexprep(body, call, ''));
      params.visualization = 0;
      r = tracker(params);
    case 'bacf'
      addpath(genpath(code_dir));  % as their ARCF_Demo_single_seq.m does
      video_path = seq.video_path;
      body = regexprep(fileread('run_ARCF_H.m'), '^(\s*%[^\n]*\n)*\s*function[^\n]*\n', '', 'once');
      call = 'results\s*=\s*tracker_HOG\(params\);';
      if numel(regexp(body, call)) ~= 1, error('authors_run: unexpected run_ARCF_H.m'); end
      eval(regexprep(body, call, ''));
      params.admm_gamma = 0;         % no aberrance term: BACF's filter update
      params.learning_rate = 0.013;  % run_BACF.m's (ARCF's is 0.019)
      params.visualization = 0;
      r = tracker_HOG(params);
    case 'arcf'
      addpath(genpath(code_dir));  % as their ARCF_Demo_single_seq.m does
      body = regexprep(fileread('run_ARCF.m'), '^(\s*%[^\n]*\n)*\s*function[^\n]*\n', '', 'once');
      call = 'results\s*=\s*tracker_HOGCN\(params\);';
      if numel(regexp(body, call)) ~= 1, error('authors_run: unexpected run_ARCF.m'); end
      eval(regexprep(body, call, ''));  % its settings, params.seq = seq included
      params.visualization = 0;
      r = tracker_HOGCN(params);
    case 'autotrack'
      r = run_AutoTrack(seq);  % adds its feature/, implementation/, utils/; visualization off
    case 'eco_hc'
      setup_paths();  % theirs: implementation/, feature_extraction/, external_libs/, utils/
      body = regexprep(fileread(fullfile('runfiles', 'testing_ECO_HC.m')), '^\s*function[^\n]*\n', '', 'once');
      call = 'results\s*=\s*tracker\(params\);';
      if numel(regexp(body, call)) ~= 1, error('authors_run: unexpected testing_ECO_HC.m'); end
      eval(regexprep(body, call, ''));  % its settings, params.seq = seq included
      params.visualization = 0;
      % tracker.m falls back to imresize, silently here, when mexResize does not run
      if exist('mexResize') ~= 3, error('authors_run: mexResize.mex is not built'); end
      r = tracker(params);
    case 'csrdcf'
      r = run_csr(code_dir, seq);
    case 'dr2track'
      addpath(fullfile(code_dir, 'utils'));
      r = run_DR2Track(seq);  % its visualization is already off
    otherwise
      error('authors_run: unknown tracker %s', tracker_name);
  end
  cd(old);
  dlmwrite(out_file, r.res, 'precision', '%.4f');
  printf('fps %.4f\n', r.fps);
end

function r = run_csr(code_dir, seq)
% CSR-DCF as their demo_csr.m runs it, without its display and failure reinitialisation: the
% first frame's 1-based box initialises, every other frame is tracked; the fps counts the time
% inside their two calls, as the demo's tic/toc does.
  addpath(code_dir, fullfile(code_dir, 'mex'), fullfile(code_dir, 'utils'), fullfile(code_dir, 'features'));
  addpath(fullfile(code_dir, 'octave_shims'));  % MATLAB's imresize and strel('disk', 1), hann
  n = numel(seq.s_frames);
  res = zeros(n, 4); res(1, :) = seq.init_rect;
  t = 0;
  for k = 1:n
    img = imread(seq.s_frames{k});
    tic();
    if k == 1
      tracker = create_csr_tracker(img, seq.init_rect);
    else
      [tracker, res(k, :)] = track_csr_tracker(tracker, img);
    end
    t = t + toc();
  end
  r = struct('res', res, 'fps', n / t);
end
