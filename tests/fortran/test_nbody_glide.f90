!> The N-body engine's closed-form steps (impact1d_nbody_glide): run_nbody on one- and
!> two-body scenes under constant forces glides (run_stats%glided) and gives the samples
!> and events of the run that locates every step, bit for bit, at dt = 1e-3 and 0.1; a free
!> flight glides every step and ends on its closed form; a body pushed onto a wall hits it
!> at the closed form's instant and speed. Under force tables the same: case 6's triangle
!> (the blocks rattling in their slot, sliding and sticking) and a ramp against two blocks
!> held by static friction (the held mode checked once a segment, not every step) glide and
!> give the located run's bits; a ramp's free flight ends on its cubic.
program test_nbody_glide
  use, intrinsic :: iso_fortran_env, only: int64
  use impact1d_kinds, only: wp
  use impact1d_error, only: error_type
  use impact1d_scene, only: scene_type
  use impact1d_forcing, only: table_type
  use impact1d_output, only: memory_sink, run_stats, start_counts, row_length
  use impact1d_nbody_solver, only: run_nbody
  use testing, only: check, finish, two_body
  implicit none
  character(len=*), parameter :: dts(2) = ['1e-3', '0.1 ']
  integer :: j
  type(table_type) :: triangle, ramp
  triangle%t = [0.0_wp, 1.0_wp, 2.0_wp, 3.0_wp, 4.0_wp]
  triangle%f = [0.0_wp, 30.0_wp, 0.0_wp, -30.0_wp, 0.0_wp]
  ramp%t = [0.0_wp, 10.0_wp]
  ramp%f = [0.0_wp, 40.0_wp]

  do j = 1, size(dts)
    ! Two bodies: walls, the link's slot, friction, forces toward each other (case 5's
    ! rattle, with friction).
    call same_bits('x_left = -0.5, r_left = 0.5, x_right = 2, r_right = 0.7, d_min = 0.2, r_min = 0.6, ' // &
      'd_max = 1.5, r_max = 0.8, mu1 = 0.1, mu2 = 0.05, g = 10, f1 = 2, f2 = -3, v1 = 0.5, t_end = 3, dt = ' // &
      trim(dts(j)), .false.)
    ! Static friction above sliding: a body slides to a stop and sticks.
    call same_bits('mu1 = 0.2, mus1 = 0.3, mu2 = 0.1, g = 10, v1 = 2, v2 = -1, f2 = 0.5, d_min = 0.1, ' // &
      't_end = 2, dt = ' // trim(dts(j)), .false.)
    ! One body between two walls under a force, bouncing to rest on one of them.
    call same_bits('x_left = -1, r_left = 0.5, x_right = 1, r_right = 0.9, v1 = 3, f1 = -2, mu1 = 0.05, g = 10, ' // &
      't_end = 4, dt = ' // trim(dts(j)), .true.)
    ! Tables: case 6 (walls, the slot, friction, the triangle on body 1); the break-away
    ! (stuck under the ramp until 3.25 s, then sliding together).
    call same_bits('m2 = 2, mu1 = 1, mu2 = 1, g = 10, x_left = 0, r_left = 1, x_right = 10, r_right = 1, ' // &
      'd_min = 0, r_min = 1, d_max = 2, r_max = 1, x1 = 1, x2 = 2, t_end = 5, dt = ' // trim(dts(j)), .false., triangle)
    call same_bits('m2 = 2, mu1 = 0.3, mus1 = 0.5, mu2 = 0.2, mus2 = 0.4, g = 10, x1 = 0, x2 = 0, t_end = 5, dt = ' // &
      trim(dts(j)), .false., ramp)
  end do
  call free_flight()
  call resting_clock()
  call ramp_flight(ramp)
  call wall_hit()
  call finish('test_nbody_glide')

contains

  !> A run of scene (two_body's assignments) by run_nbody, its samples and events.
  subroutine run_scene(scene, closed_form, sink, stats)
    type(scene_type), intent(in) :: scene
    logical, intent(in) :: closed_form
    type(memory_sink), intent(out) :: sink
    type(run_stats), intent(out) :: stats
    type(error_type), allocatable :: error
    integer :: k
    call sink%reserve(scene%n_samples, [(k, k = 1, row_length(scene%n_bodies))])
    sink%row_names = scene%row_name
    call start_counts(stats, scene%n_rows + scene%n_stops, scene%n_bodies, scene%n_frictions)
    call run_nbody(scene, sink, stats, error, closed_form)
    call check(.not. allocated(error), 'run_nbody ran')
  end subroutine run_scene

  !> With and without the closed-form steps: the same samples and events to the bit, the
  !> same steps, and some of them glided.
  subroutine same_bits(assignments, one_body, f1_table)
    character(len=*), intent(in) :: assignments
    logical, intent(in) :: one_body
    type(table_type), intent(in), optional :: f1_table
    type(scene_type) :: scene
    type(memory_sink) :: glided, located
    type(run_stats) :: with, without
    call two_body(assignments, scene, f1_table, one_body=one_body)
    call run_scene(scene, .true., glided, with)
    call run_scene(scene, .false., located, without)
    call check(with%glided > 0 .and. without%glided == 0, 'glides: ' // assignments)
    call check(with%steps == without%steps, 'the same steps: ' // assignments)
    call check(glided%n_samples == located%n_samples .and. glided%n_events == located%n_events .and. &
      glided%n_events > 0, 'the same counts: ' // assignments)
    if (glided%n_samples /= located%n_samples .or. glided%n_events /= located%n_events) return
    call check(all(glided%samples(:glided%n_samples, :) == located%samples(:located%n_samples, :)), &
      'the same samples, bit for bit: ' // assignments)
    call check(all(glided%event_time(:glided%n_events) == located%event_time(:located%n_events)) .and. &
      all(glided%event_class(:glided%n_events) == located%event_class(:located%n_events)) .and. &
      all(glided%event_index(:glided%n_events) == located%event_index(:located%n_events)) .and. &
      all(glided%event_v(:, :glided%n_events) == located%event_v(:, :located%n_events)), &
      'the same events, bit for bit: ' // assignments)
  end subroutine same_bits

  !> Bodies stuck from the start (the tutorial's case 1: forces within their friction
  !> bounds), where the glide moves the clock alone once the state is closed_step's fixed
  !> point: the located run's samples to the bit, a zero's sign too (body 1 starts at x =
  !> -0, which a step makes +0: the fixed point comes only after it).
  subroutine resting_clock()
    character(len=*), parameter :: assignments = 'm2 = 2, mu1 = 1, mu2 = 1, g = 10, f1 = 6, f2 = -10, ' // &
      'x1 = 0, x2 = 2.5, t_end = 1, dt = 1e-3'
    type(scene_type) :: scene
    type(memory_sink) :: glided, located
    type(run_stats) :: with, without
    call two_body(assignments, scene)
    ! (set in the built scene: the input's -0.0 is read as 0)
    scene%body_x0(1) = sign(0.0_wp, -1.0_wp)
    call run_scene(scene, .true., glided, with)
    call run_scene(scene, .false., located, without)
    call check(with%glided > 0 .and. with%steps == without%steps .and. glided%n_samples == located%n_samples, &
      'glides, the same steps and samples: ' // assignments)
    if (glided%n_samples /= located%n_samples) return
    associate (a => glided%samples(:glided%n_samples, :), b => located%samples(:located%n_samples, :))
      call check(all(a == b) .and. all(sign(1.0_wp, a) == sign(1.0_wp, b)), &
        'the same samples, bit for bit (signs of zeros too): ' // assignments)
      call check(sign(1.0_wp, a(1, 2)) < 0.0_wp .and. sign(1.0_wp, a(2, 2)) > 0.0_wp, &
        'x1 starts at -0 and a step makes it +0 (the check can fail): ' // assignments)
    end associate
  end subroutine resting_clock

  !> Two bodies far from every limit under constant forces: every step glided; the end on
  !> x0 + v0 t + f t^2 / (2 m) to rounding.
  subroutine free_flight()
    type(scene_type) :: scene
    type(memory_sink) :: sink
    type(run_stats) :: stats
    real(wp), parameter :: t = 2.0_wp
    real(wp) :: x1, x2
    call two_body('m2 = 2, v1 = 0.25, v2 = 0.5, f1 = 0.75, f2 = 1.5, t_end = 2, dt = 1e-3, dt_out = 0.5', scene)
    call run_scene(scene, .true., sink, stats)
    call check(stats%glided == stats%steps .and. stats%steps == 2000_int64, 'a free flight glides every step')
    x1 = 0.25_wp * t + 0.75_wp * t**2 / 2.0_wp
    x2 = 1.0_wp + 0.5_wp * t + 1.5_wp / 2.0_wp * t**2 / 2.0_wp
    associate (last => sink%samples(sink%n_samples, :))
      call check(abs(last(1) - t) == 0.0_wp, 'ends at t_end')
      call check(abs(last(2) - x1) <= 4.0_wp * epsilon(1.0_wp) * abs(x1) .and. &
        abs(last(4) - x2) <= 4.0_wp * epsilon(1.0_wp) * abs(x2), 'free flight: x on the closed form')
      call check(abs(last(3) - (0.25_wp + 0.75_wp * t)) <= 4.0_wp * epsilon(1.0_wp) .and. &
        abs(last(5) - (0.5_wp + 0.75_wp * t)) <= 4.0_wp * epsilon(1.0_wp), 'free flight: v on the closed form')
    end associate
  end subroutine free_flight

  !> One body from rest 0.5 m from the left wall (r = 0.5) under -2 N (1 kg): the wall at
  !> t = sqrt(1/2) s at sqrt(2) m/s (inside a step), the steps before it glided, at dt = 0.1
  !> as at 1e-3.
  subroutine wall_hit()
    type(scene_type) :: scene
    type(memory_sink) :: sink
    type(run_stats) :: stats
    integer :: k
    do k = 1, size(dts)
      call two_body('x1 = 0, x_left = -0.5, r_left = 0.5, f1 = -2, t_end = 1.2, dt = ' // trim(dts(k)), scene, &
        one_body=.true.)
      call run_scene(scene, .true., sink, stats)
      call check(stats%glided > 0 .and. sink%n_events >= 1, 'the wall met after glided steps, dt = ' // dts(k))
      if (sink%n_events < 1) cycle
      call check(abs(sink%event_time(1) - sqrt(0.5_wp)) <= 1.0e-14_wp, 'the wall met at t = sqrt(1/2) s, dt = ' // &
        dts(k))
      ! (the pair reported: body 1 and the ground; v before, after)
      call check(abs(sink%event_v(1, 1) + sqrt(2.0_wp)) <= 1.0e-13_wp .and. &
        abs(sink%event_v(3, 1) - sqrt(0.5_wp)) <= 1.0e-13_wp, 'at -sqrt(2) m/s, back at sqrt(1/2), dt = ' // dts(k))
    end do
  end subroutine wall_hit

  !> One body of 1 kg from rest under the ramp f = 4 t N, nothing near: x = 2 t^3 / 3,
  !> v = 2 t^2; all but the steps at the samples' and corners' ends glided.
  subroutine ramp_flight(ramp)
    type(table_type), intent(in) :: ramp
    type(scene_type) :: scene
    type(memory_sink) :: sink
    type(run_stats) :: stats
    real(wp), parameter :: t = 2.0_wp
    call two_body('x1 = 0, t_end = 2, dt = 1e-3, dt_out = 0.5', scene, ramp, one_body=.true.)
    call run_scene(scene, .true., sink, stats)
    call check(stats%glided == stats%steps .and. stats%steps == 2000_int64, 'a ramp''s flight glides every step')
    associate (last => sink%samples(sink%n_samples, :))
      call check(last(1) == t, 'ramp: ends at t_end')
      call check(abs(last(2) - 2.0_wp * t**3 / 3.0_wp) <= 8.0_wp * epsilon(1.0_wp) * 2.0_wp * t**3 / 3.0_wp, &
        'ramp: x on the cubic')
      call check(abs(last(3) - 2.0_wp * t**2) <= 8.0_wp * epsilon(1.0_wp) * 2.0_wp * t**2, 'ramp: v on the parabola')
    end associate
  end subroutine ramp_flight
end program test_nbody_glide
