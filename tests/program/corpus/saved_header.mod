%%%
  VERSION:1
  LANGUAGE:ENGLISH
%%%

MODULE SavedHeader
    ! As the controller saves a module: the %%% header, an ERROR handler.
    CONST robtarget pA := [[375, 0, 540], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pB := [[300, 150, 400], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    PROC main()
        MoveJ pA, vmax, z50, tool0;
        MoveL pB, v500, fine, tool0;
    ERROR
        IF ERRNO = ERR_PATH_STOP THEN
            StartMove;
            RETRY;
        ENDIF
    ENDPROC
ENDMODULE
