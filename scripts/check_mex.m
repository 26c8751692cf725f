% The MATLAB/Octave export of soft_finger, checked in Octave:
%
%   octave --no-gui --quiet scripts/check_mex.m DIR SOFTARM_BIN TRAJECTORY_CSV
%
% DIR holds `softarm export soft_finger --set SET --mex DIR`, built;
% TRAJECTORY_CSV is `softarm simulate soft_finger --set SET --t-end 2
% --rtol 1e-10 --atol 1e-12 --output-dt 0.01`'s trajectory.csv, SET the
% bending damping below: the damped finger suits ode15s (BDF), which an
% undamped one holds to steps far below its swing.
% At random states, M and h agree with `softarm eom` to 1e-12 of their
% largest entry, the accelerations and the Jacobian (solves with M) to
% 1e-9; then ode15s integrates the MEX function for 2 s and its tip
% follows softarm's run.
args = argv();
dir = args{1}; bin = args{2}; trajectory = args{3};
set = 'segment.0.bending_damping=1e-5';
addpath(dir);
n = numel(soft_finger_mex('coordinate_names'));
rand('state', 7);

function check(what, got, ref, tol)
  scale = max(abs(ref(:)));
  err = max(abs(got(:) - ref(:)));
  printf('%-14s largest difference %.3e of %.3e\n', what, err, scale);
  if ~(err <= tol * scale)
    error('%s: the MEX function and softarm differ by %g of %g', what, err, scale);
  end
end

function s = joined(v)
  s = strjoin(arrayfun(@(x) sprintf('%.17g', x), v(:)', 'UniformOutput', false), ',');
end

for k = 1:3
  q = 0.6 * rand(n, 1) - 0.3;
  qd = 2 * rand(n, 1) - 1;
  t = 0.3;
  [status, text] = system(sprintf('%s eom soft_finger --set %s --q %s --qd %s --t %.17g --json', ...
                                  bin, set, joined(q), joined(qd), t));
  if status ~= 0, error('softarm eom failed: %s', text); end
  ref = jsondecode(text);
  check('mass', soft_finger_mass(t, q), ref.mass, 1e-12);
  check('bias', soft_finger_bias(t, q, qd), ref.bias, 1e-12);
  check('outputs', soft_finger_outputs(t, q, qd), ref.outputs, 1e-12);
  dx = soft_finger_state_derivative(t, [q; qd]);
  check('accelerations', dx(n + 1:end), ref.accelerations, 1e-9);
  check('jacobian', soft_finger_jacobian(t, [q; qd]), ref.jacobian, 1e-9);
end

% ode15s on the MEX function and its Jacobian, against softarm's run.
% Octave's ode15s starts from the slope it is given (zero by default):
% give it f(0, x0).
x0 = zeros(2 * n, 1);
opts = odeset('RelTol', 1e-10, 'AbsTol', 1e-12, 'Jacobian', @(t, x) soft_finger_jacobian(t, x), ...
              'InitialSlope', soft_finger_state_derivative(0, x0));
[tt, X] = ode15s(@(t, x) soft_finger_state_derivative(t, x), [0 2], x0, opts);
tips = zeros(numel(tt), 2);
for i = 1:numel(tt)
  o = soft_finger_outputs(tt(i), X(i, 1:n)', X(i, n + 1:end)');
  tips(i, :) = o(1:2)';
end
fid = fopen(trajectory);
header = strsplit(fgetl(fid), ',');
fclose(fid);
run = dlmread(trajectory, ',', 1, 0);
cols = [find(strcmp(header, 'tip_x')), find(strcmp(header, 'tip_y'))];
% ode15s's own steps, the tip between them by a spline, at softarm's times.
at = interp1(tt, tips, run(:, 1), 'spline');
err = max(max(abs(at - run(:, cols))));
printf('ode15s, 2 s in %d steps: the tip within %.3e m of softarm simulate (%d times)\n', ...
       numel(tt), err, size(run, 1));
if ~(err <= 1e-6), error('ode15s and softarm simulate differ by %g m', err); end
