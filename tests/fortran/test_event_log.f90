!> The event log's bookkeeping: a pending rest is logged when its time comes; a release
!> waits for time to move on and a rest at the same instant cancels it.
program test_event_log
  use impact1d_kinds, only: wp
  use impact1d_scene, only: scene_type
  use impact1d_output, only: memory_sink, run_stats, class_rest, event_name, start_counts
  use impact1d_event_log, only: event_log_type
  use testing, only: check, finish, two_body, row_of
  implicit none
  type(event_log_type) :: event_log
  type(memory_sink) :: sink
  type(run_stats) :: stats
  type(scene_type) :: scene
  integer :: left

  call two_body('x_left = -1', scene)
  left = row_of(scene, 'left')
  call event_log%allocate_log(scene%n_rows, scene%n_bodies)
  call sink%reserve(4, [1, 2, 3])   ! (samples are not used here)
  sink%row_names = scene%row_name
  call start_counts(stats, scene%n_rows, scene%n_bodies)
  event_log%pending_rest(left) = 3.0_wp
  call event_log%flush_pending_rest(scene, 2.5_wp, [0.0_wp, 1.0_wp], sink, stats)
  call check(sink%n_events == 0, 'no rest before t = 3')
  call event_log%flush_pending_rest(scene, 3.0_wp, [0.0_wp, 1.0_wp], sink, stats)
  call check(sink%n_events == 1, 'rest_left at t = 3')
  if (sink%n_events == 1) call check(sink%event_class(1) == class_rest .and. sink%event_index(1) == left .and. &
    event_name(sink%row_names, sink%event_class(1), sink%event_index(1)) == 'rest_left' .and. &
    all(sink%event_ends(:, 1) == [1, 2]), 'logged as rest_left, reporting bodies 1 and 2')
  call check(stats%row_events(class_rest, left) == 1 .and. stats%n_events == 1, 'counted as a rest on left')

  ! Released at t = 4, resting again at the same instant: neither is logged.
  event_log%release_time(left) = 4.0_wp
  call event_log%begin_rest(scene, left, 4.0_wp, 4.0_wp, [0.0_wp, 0.0_wp], sink, stats)
  call event_log%flush_releases(scene, 5.0_wp, .true., sink, stats)
  call check(sink%n_events == 1, 'a release and a rest at one instant cancel')
  call finish('test_event_log')
end program test_event_log
