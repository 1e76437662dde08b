!> impact1d command line: a thin main over the library. Reads a scene, applies the options,
!> streams the run to OUT.dat and OUT.events.dat, prints a summary. Any error: one line on
!> stderr and a non-zero exit status (1 bad input, 2 the run could not go on).
program impact1d_cli
  use, intrinsic :: iso_fortran_env, only: error_unit, output_unit
  use, intrinsic :: iso_c_binding, only: c_int
  use impact1d_kinds, only: wp
  use impact1d_error, only: error_type, status_input, fmt
  use impact1d_scene, only: scene_input, scene_type, i_t_end, i_dt, i_dt_out, i_method, i_title
  use impact1d_io, only: read_scene_file, prepare_scene
  use impact1d_output, only: file_sink, make_folder, event_names, n_event_kinds
  use impact1d_solver, only: run, run_stats
  implicit none

  interface
    subroutine c_exit(status) bind(C, name='exit')
      import :: c_int
      integer(c_int), value :: status
    end subroutine c_exit
    integer(c_int) function c_isatty(fd) bind(C, name='isatty')
      import :: c_int
      integer(c_int), value :: fd
    end function c_isatty
  end interface

  character(len=*), parameter :: usage = &
    'usage: impact1d SCENE [--t-end T] [--dt DT] [--dt-out DT_OUT] [--method event] [-o OUT.dat]'
  type(scene_input) :: input
  type(scene_type) :: scene
  type(file_sink) :: sink
  type(run_stats) :: stats
  type(error_type), allocatable :: error, close_error
  character(len=:), allocatable :: scene_path, out_path, option, value
  character(len=4096) :: argument
  integer :: i, n_args, k
  real(wp) :: overrides(3)
  logical :: overridden(3)
  character(len=64) :: method

  overridden = .false.
  overrides = 0.0_wp
  method = ''
  scene_path = ''
  out_path = ''
  n_args = command_argument_count()
  i = 1
  do while (i <= n_args)
    call get_command_argument(i, argument)
    option = trim(argument)
    select case (option)
    case ('-h', '--help')
      write(output_unit, '(a)') usage
      write(output_unit, '(a)') 'Writes OUT.dat (default output/SCENE_NAME.dat) and OUT.events.dat; options override &run.'
      stop
    case ('--t-end', '--dt', '--dt-out', '--method', '-o')
      if (i == n_args) call fail(status_input, option // ' needs a value')
      call get_command_argument(i + 1, argument)
      value = trim(argument)
      i = i + 2
      select case (option)
      case ('--method')
        method = value
      case ('-o')
        out_path = value
      case ('--t-end')
        call override(1)
      case ('--dt')
        call override(2)
      case ('--dt-out')
        call override(3)
      end select
    case default
      if (len(option) > 1) then
        if (option(1:1) == '-') call fail(status_input, 'unknown option ' // option // '; ' // usage)
      end if
      if (len(option) == 0) call fail(status_input, 'an empty argument is not a scene; ' // usage)
      if (len(scene_path) > 0) call fail(status_input, 'one scene at a time; ' // usage)
      scene_path = option
      i = i + 1
    end select
  end do
  if (len(scene_path) == 0) call fail(status_input, usage)

  call read_scene_file(scene_path, input, error)
  if (allocated(error)) call fail(error%status, error%message)
  input%value([i_t_end, i_dt, i_dt_out]) = merge(overrides, input%value([i_t_end, i_dt, i_dt_out]), overridden)
  input%given([i_t_end, i_dt, i_dt_out]) = input%given([i_t_end, i_dt, i_dt_out]) .or. overridden
  if (len_trim(method) > 0) input%text(i_method) = method
  call prepare_scene(input, scene, error)
  if (allocated(error)) call fail(error%status, scene_path // ': ' // error%message)

  if (len(out_path) == 0) then
    call make_folder('output')
    out_path = 'output/' // stem(scene_path) // '.dat'
  end if
  call sink%open(out_path, input, error)
  if (allocated(error)) call fail(error%status, error%message)
  ! Progress only where a person watches: stderr a terminal (file descriptor 2).
  sink%show_progress = c_isatty(2_c_int) == 1
  call run(scene, sink, stats, error)
  call sink%close(.not. allocated(error), close_error)
  if (allocated(error)) call fail(error%status, scene_path // ': ' // error%message)
  if (allocated(close_error)) call fail(close_error%status, close_error%message)
  call summary()

contains

  subroutine summary()
    character(len=:), allocatable :: line
    write(output_unit, '(a)') 'impact1d: ' // trim(input%text(i_title))
    write(output_unit, '(a)') '  scene     ' // scene_path // ' (method ' // scene%method // ', dt = ' // &
      fmt(scene%dt) // ' s, t_end = ' // fmt(scene%t_end) // ' s)'
    write(output_unit, '(a)') '  output    ' // out_path // ' (' // fmt(scene%n_samples) // ' rows every ' // &
      fmt(scene%dt_out) // ' s) and its events file (' // fmt(sum(stats%events)) // ' events)'
    line = ''
    do k = 1, n_event_kinds
      if (stats%events(k) > 0) line = line // ' ' // trim(event_names(k)) // ' ' // fmt(stats%events(k))
    end do
    if (len(line) == 0) line = ' none'
    write(output_unit, '(a)') '  events   ' // line
    write(output_unit, '(a, 5(a, es12.5))') '  final    ', ' t =', stats%last_row(1), '  x1 =', stats%last_row(2), &
      '  v1 =', stats%last_row(3), '  x2 =', stats%last_row(4), '  v2 =', stats%last_row(5)
    write(output_unit, '(a, es12.5, a)') '  energy     KE =', stats%last_row(6), ' J'
    write(output_unit, '(a, 3(a, es12.5), a, es9.2, a)') '  ledger   ', ' work =', stats%last_row(7), &
      '  friction loss =', stats%last_row(8), '  impact loss =', stats%last_row(9), &
      '  |residual| <=', stats%max_residual, ' J'
    write(output_unit, '(a)') '  steps     ' // fmt(stats%steps) // ' RK4 steps'
  end subroutine summary

  !> Option k of --t-end, --dt, --dt-out takes the value just read.
  subroutine override(k)
    integer, intent(in) :: k
    overrides(k) = number(option, value)
    overridden(k) = .true.
  end subroutine override

  real(wp) function number(name, text)
    character(len=*), intent(in) :: name, text
    integer :: ios
    read(text, *, iostat=ios) number
    if (ios /= 0) call fail(status_input, name // ' ' // text // ': not a number')
  end function number

  !> File name without folder and extension: input/case3.nml -> case3.
  function stem(path) result(name)
    character(len=*), intent(in) :: path
    character(len=:), allocatable :: name
    integer :: slash, dot
    slash = index(path, '/', back=.true.)
    name = path(slash + 1:)
    dot = index(name, '.', back=.true.)
    if (dot > 1) name = name(:dot - 1)
  end function stem

  subroutine fail(status, message)
    integer, intent(in) :: status
    character(len=*), intent(in) :: message
    write(error_unit, '(a)') 'impact1d: ' // message
    flush(error_unit)
    call c_exit(int(status, c_int))
  end subroutine fail
end program impact1d_cli
